#!/usr/bin/env python3
"""Reads the JUnit files `ctest --output-junit` writes and reports on them.

  ctest_report.py skipped FILE...        every skipped test with its reason (the first line of its
                                         output that says SKIP), one line each; exit 0
  ctest_report.py failed FILE... [--out DIR]
                                         the failed tests, one line each; with --out, each one's whole
                                         output in DIR/<name>.log; exit 0
  ctest_report.py slowest N FILE...      the N longest tests, "<seconds> s  <name>", longest first; exit 0
  ctest_report.py summary RUNS_DIR       the failures of every run of scripts/flaky.sh under RUNS_DIR
                                         (run-*/ctest.xml): each test that failed, how often, and
                                         where its output is; exit 1 when any test failed

A skip is what ctest reports as "not run" for a test whose SKIP_RETURN_CODE matched (77 here): the
reason is what the test printed (Python and shell tests: "SKIP: why"; Catch2: "SKIPPED: why").
"""
import glob
import os
import re
import sys
import xml.etree.ElementTree as ET

SKIP_LINE = re.compile(r"\bSKIP(?:PED)?\b[:\s]", re.IGNORECASE)


def cases(path, with_time=False):
    """(name, status, output) for each test case of one JUnit file; status is pass, fail or skip.
    with_time: (name, status, output, seconds)."""
    try:
        root = ET.parse(path).getroot()
    except (OSError, ET.ParseError) as e:
        print(f"ctest_report: {path}: {e}", file=sys.stderr)
        return
    for case in root.iter("testcase"):
        name = case.get("name", "?")
        out = case.findtext("system-out") or ""
        if case.find("failure") is not None or case.get("status") == "fail":
            status = "fail"
        elif case.find("skipped") is not None or case.get("status") in ("notrun", "disabled"):
            status = "skip"
        else:
            status = "pass"
        if with_time:
            try:
                seconds = float(case.get("time", "0"))
            except ValueError:
                seconds = 0.0
            yield name, status, out, seconds
        else:
            yield name, status, out


def skip_reason(output):
    for line in output.splitlines():
        if SKIP_LINE.search(line):
            return line.strip()[:300]
    return "(the test printed no SKIP line)"


def safe_name(name):
    return re.sub(r"[^A-Za-z0-9._-]+", "_", name).strip("_")[:150]


def cmd_skipped(files):
    seen = {}
    for path in files:
        for name, status, out in cases(path):
            if status == "skip":
                seen[name] = skip_reason(out)
    for name in sorted(seen):
        print(f"  {name}: {seen[name]}")
    return 0


def cmd_failed(files, out_dir):
    for path in files:
        for name, status, out in cases(path):
            if status != "fail":
                continue
            where = ""
            if out_dir:
                os.makedirs(out_dir, exist_ok=True)
                log = os.path.join(out_dir, safe_name(name) + ".log")
                with open(log, "w", encoding="utf-8") as f:
                    f.write(out)
                where = f" (output: {log})"
            print(f"  {name}{where}")
    return 0


def cmd_slowest(count, files):
    times = []
    for path in files:
        for name, _, _, seconds in cases(path, with_time=True):
            times.append((seconds, name))
    times.sort(key=lambda t: (-t[0], t[1]))
    for seconds, name in times[:count]:
        print(f"{seconds:8.2f} s  {name}")
    return 0


def cmd_summary(runs_dir):
    runs = sorted(glob.glob(os.path.join(runs_dir, "run-*", "ctest.xml")))
    failures = {}
    totals = {}
    for path in runs:
        run = os.path.basename(os.path.dirname(path))
        for name, status, _ in cases(path):
            totals[name] = totals.get(name, 0) + 1
            if status == "fail":
                failures.setdefault(name, []).append(run)
    print(f"flaky: {len(runs)} run(s), {len(totals)} test(s)")
    if not failures:
        print("flaky: no test failed")
        return 0
    print(f"flaky: {len(failures)} test(s) failed at least once:")
    for name in sorted(failures, key=lambda n: (-len(failures[n]), n)):
        runs_failed = failures[name]
        print(f"  {len(runs_failed)}/{totals[name]}  {name}")
        for run in runs_failed:
            print(f"        {os.path.join(runs_dir, run, 'failed', safe_name(name) + '.log')}")
    return 1


def main(argv):
    if len(argv) < 2 or argv[0] not in ("skipped", "failed", "slowest", "summary"):
        print(__doc__, file=sys.stderr)
        return 2
    cmd, rest = argv[0], argv[1:]
    if cmd == "skipped":
        return cmd_skipped(rest)
    if cmd == "slowest":
        if not rest[0].isdigit():
            print("ctest_report: slowest takes a count first", file=sys.stderr)
            return 2
        return cmd_slowest(int(rest[0]), rest[1:])
    if cmd == "failed":
        out_dir = None
        if "--out" in rest:
            i = rest.index("--out")
            out_dir = rest[i + 1]
            rest = rest[:i] + rest[i + 2:]
        return cmd_failed(rest, out_dir)
    return cmd_summary(rest[0])


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
