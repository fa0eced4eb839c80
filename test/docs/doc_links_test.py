#!/usr/bin/env python3
"""Every relative link in the repository's Markdown files names a file or folder that exists.

Docs cite the protocol digest (docs/protocol/wire.md), examples and tests by path; a link to a file
that moved or never was in the repository (issue 15: `wire.md §13`) fails here with file:line.
External links (http:, https:, mailto:) and in-page anchors are not checked.

Usage: doc_links_test.py REPO_ROOT
"""
import pathlib
import re
import subprocess
import sys

LINK = re.compile(r"\[[^\]]*\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)")
FENCE = re.compile(r"^\s*(```|~~~)")
CODE_SPAN = re.compile(r"`[^`]*`")


def tracked_markdown(root: pathlib.Path):
    out = subprocess.run(["git", "-C", str(root), "ls-files", "*.md"], capture_output=True, text=True)
    if out.returncode != 0:  # not a git checkout (a source tarball): every .md under the root
        return sorted(p for p in root.rglob("*.md") if "build" not in p.relative_to(root).parts[:1])
    return [root / line for line in out.stdout.splitlines() if line]


def broken_links(md: pathlib.Path):
    in_fence = False
    for n, line in enumerate(md.read_text(encoding="utf-8").splitlines(), 1):
        if FENCE.match(line):
            in_fence = not in_fence
            continue
        if in_fence:
            continue
        for target in LINK.findall(CODE_SPAN.sub("", line)):
            if re.match(r"^[a-z][a-z0-9+.-]*:", target) or target.startswith("#"):
                continue
            path = target.split("#", 1)[0]
            if path and not (md.parent / path).exists():
                yield n, target


def main():
    root = pathlib.Path(sys.argv[1]).resolve()
    files = tracked_markdown(root)
    bad = [(md, n, t) for md in files for n, t in broken_links(md)]
    for md, n, t in bad:
        print(f"{md.relative_to(root)}:{n}: link to a missing file: {t}")
    print(f"doc links: {len(files)} Markdown files, {len(bad)} broken relative links")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
