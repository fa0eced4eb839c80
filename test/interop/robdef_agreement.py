#!/usr/bin/env python3
"""Agreement with the official service definition parser and verifier.

Every case is a set of service definition texts. The official library (`robotraconteur` from the
venv) gives its verdict: `parse` (ServiceDefinition.FromString rejects a text), `verify`
(RobotRaconteurNode.RegisterServiceTypes rejects the set, which runs VerifyServiceDefinitions) or
`accept`. Ours comes from rr_robdef_verdicts (test/interop/robdef_verdicts.cpp: our parser and
verifier on the same bytes). Accept or reject must agree on every case; where both reject at
different stages (parse vs verify) the case is listed but passes.

One official bug is allowed for (robdef.md §4.1): registration prints each definition with
ServiceDefinition::ToString, which throws for `objref T[]{int32}` although the parser and the
verifier accept it. A set whose only failure is that ToString error counts as verified (the
official client side only parses received definitions and works with it).

Then "never emit what the official library rejects": for every case we accept, our canonical text of
each definition (robdef/canonical_text.hpp) must parse with the official parser, and the canonical
set must get the same official verdict as the original.

Corpus: the edge cases below (`--cases edge`), and with `--cases standard` the standard robdefs from
--standard (../shared/robdef-standard: each group-1 file with the files it imports, all of group 1,
each group-2 file with group 1) plus the seed paper's examples and our interop robdef when given.

Exit status: 0 all agree, 1 a disagreement, 77 skipped (official package or corpus folder missing).

With --rr-robdef (edge cases), a few files are also read as files: the official
ReadServiceDefinitionFile against `rr-robdef check` (a leading UTF-8 byte-order mark is dropped by
both; in text, as from the wire, both reject it).

Usage: robdef_agreement.py --verdicts PATH [--cases edge|standard] [--standard DIR]
                           [--extra FILE ...] [--rr-robdef PATH] [--verbose] [--keep DIR]
"""

import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile

BOM = "\ufeff"
H10 = "service t.a\nstdver 0.10\n"
H092 = "service t.a\nstdver 0.9.2\n"
H09 = "service t.a\nstdver 0.9\n"
HNONE = "service t.a\n"
OBJ2 = H10 + "object O2\nend\n"


def objref(line, header=OBJ2):
    return header + "object O\n    " + line + "\nend\n"


def const(t, v, header=H10):
    return header + "constant " + t + " c " + v + "\n"


# (name, [texts]). Names are unique and become folder names.
EDGE_CASES = [
    # --- 8-bit integer constants (the official conversion reads int8/uint8 as one character)
    *[(f"const {t} {v}", [const(t, v)]) for t, v in [
        ("int8", "0"), ("int8", "9"), ("int8", "10"), ("int8", "127"), ("int8", "-1"), ("int8", "-0"),
        ("int8", "+1"), ("int8", "0x1"), ("int8", "-128"), ("uint8", "5"), ("uint8", "255"),
        ("uint8", "0xFF"), ("uint8", "-1"), ("uint8", "00"),
        ("int8[]", "{1, 2, 3}"), ("int8[]", "{1, 20}"), ("int8[]", "{-1}"), ("int8[]", "{}"),
        ("int8[]", "{ }"), ("uint8[]", "{0,9}"), ("uint8[]", "{255}"), ("uint8[]", "{0x1}"),
        ("uint8[2]", "{1,2}"), ("uint8[2-]", "{1,2,3}"), ("uint8[3]", "{1}"), ("uint8[]", "{1,,2}"),
        ("uint8[]", "{1,}"), ("int8[*]", "{1}"), ("uint8{list}", "{1}"),
    ]],
    ("const int8 in struct", [H10 + "struct S\n    constant int8 c 5\n    field int32 x\nend\n"]),
    ("const int8 12 in struct", [H10 + "struct S\n    constant int8 c 12\n    field int32 x\nend\n"]),
    ("const uint8[] 12 in object", [H10 + "object O\n    constant uint8[] c {1, 12}\nend\n"]),
    ("legacy option constant int8 12", [HNONE + "option constant int8 c 12\n"]),
    ("legacy option constant int8 1", [HNONE + "option constant int8 c 1\n"]),
    ("legacy object option constant uint8 200", [HNONE + "object O\n    option constant uint8 c 200\nend\n"]),
    # --- neighbours: other integer widths, signs, hex, floats
    *[(f"const {t} {v}", [const(t, v)]) for t, v in [
        ("int16", "-1"), ("int16", "32767"), ("int16", "32768"), ("int16", "-32768"), ("int16", "-32769"),
        ("uint16", "-1"), ("uint16", "-65535"), ("uint16", "-65536"), ("uint16", "65536"),
        ("int16", "0x7fff"), ("int16", "0x8000"), ("int16", "-0x8000"), ("int16", "-0x8001"),
        ("uint16", "0xffff"), ("uint16", "0x10000"), ("uint16", "-0x1"), ("uint16", "-0xffff"),
        ("uint16", "-0x10000"), ("int16", "+0x10"), ("int16", "0X10"), ("int16", "0x"), ("int16", "01"),
        ("int32", "0x80000000"), ("int32", "-0x80000000"), ("int32", "2147483648"), ("uint32", "-1"),
        ("uint32", "4294967295"), ("uint32", "4294967296"), ("int64", "9223372036854775807"),
        ("int64", "-9223372036854775808"), ("int64", "9223372036854775808"),
        ("int64", "-9223372036854775809"), ("uint64", "18446744073709551615"),
        ("uint64", "18446744073709551616"), ("uint64", "-1"), ("uint64", "-18446744073709551615"),
        ("uint64", "0xffffffffffffffff"), ("uint64", "0x10000000000000000"), ("int64", "-0x8000000000000000"),
        ("int16[]", "{0x10, -0x10, +5}"), ("uint32[]", "{-1, 0xffffffff}"),
        ("double", "1."), ("double", ".5"), ("double", "-.5"), ("double", "1e400"), ("double", "1e-400"),
        ("double", "01.5"), ("double", "0x10"), ("double", "inf"), ("double", "nan"), ("double", "1e5"),
        ("single", "3.5e38"), ("single", "1e-50"), ("single", "3.4e38"), ("double[]", "{1, 2.5, -3e2}"),
        ("double[]", "{1e400}"), ("bool", "1"), ("cdouble", "1"), ("string", '"a\\tb"'),
        ("string", '"a\\qb"'), ("string", '"\\u00e9"'), ("string", '"a"b"'), ("string[]", '{"a"}'),
    ]],
    # --- `option` lines and stdver
    ("option above stdver 0.10", ["service t.a\noption foo\nstdver 0.10\n"]),
    ("option above stdver 0.9.2", ["service t.a\noption foo bar\nstdver 0.9.2\n"]),
    ("option above stdver 0.9", ["service t.a\noption foo\nstdver 0.9\n"]),
    ("option below stdver 0.10", [H10 + "option foo\n"]),
    ("option below stdver 0.9.2", [H092 + "option foo\n"]),
    ("option below stdver 0.9", [H09 + "option foo\n"]),
    ("option between stdver 0.9 and 0.10", ["service t.a\nstdver 0.9\noption foo\nstdver 0.10\n"]),
    ("option between stdver 0.10 and 0.9", ["service t.a\nstdver 0.10\noption foo\nstdver 0.9\n"]),
    ("two options above stdver 0.10", ["service t.a\noption a\noption b\nstdver 0.10\nstruct S\n    field int32 x\nend\n"]),
    ("option above stdver, import below", ["service t.a\noption foo\nstdver 0.10\nimport t.b\n",
                                           "service t.b\nstdver 0.10\n"]),
    ("option version above stdver", ["service t.a\noption version 0.9\nstdver 0.10\n"]),
    ("option version below stdver 0.9", [H09 + "option version 0.9\n"]),
    ("option version 0.8", ["service t.a\noption version 0.8\n"]),
    ("option version 1.2.9", ["service t.a\noption version 1.2.9\n"]),
    ("option version x", ["service t.a\noption version x\n"]),
    ("option constant above stdver 0.10", ["service t.a\noption constant int32 c 5\nstdver 0.10\n"]),
    ("option constant int8 12 above stdver 0.10", ["service t.a\noption constant int8 c 12\nstdver 0.10\n"]),
    ("option before service", ["option foo\nservice t.a\nstdver 0.10\n"]),
    ("option in struct stdver 0.10", [H10 + "struct S\n    option foo\n    field int32 x\nend\n"]),
    ("option in struct stdver 0.9", [H09 + "struct S\n    option foo\n    field int32 x\nend\n"]),
    ("option in object no stdver", [HNONE + "object O\n    option foo\n    property int32 x\nend\n"]),
    ("option pipe unreliable stdver 0.9", [H09 + "object O\n    option pipe p unreliable\n    pipe double p\nend\n"]),
    ("option ending in backslash above stdver", ["service t.a\noption foo\\\n\nstdver 0.10\n"]),
    ("stdver twice", ["service t.a\nstdver 0.9\nstdver 0.10\n"]),
    ("stdver after import", ["service t.a\nimport t.b\nstdver 0.10\n", "service t.b\nstdver 0.10\n"]),
    ("stdver 0.8", ["service t.a\nstdver 0.8\n"]),
    ("stdver 1.2.8", ["service t.a\nstdver 1.2.8\n"]),
    ("stdver 1.2.9", ["service t.a\nstdver 1.2.9\n"]),
    ("stdver 1.2.10", ["service t.a\nstdver 1.2.10\n"]),
    ("stdver 2.0", ["service t.a\nstdver 2.0\n"]),
    ("stdver 0.10.0.0", ["service t.a\nstdver 0.10.0.0\n"]),
    ("stdver 0.10.0.0.0", ["service t.a\nstdver 0.10.0.0.0\n"]),
    ("end struct with option above stdver 0.10", ["service t.a\noption a\nstdver 0.10\nstruct S\n    field int32 x\nend struct\n"]),
    ("end struct stdver 0.9", [H09 + "struct S\n    field int32 x\nend struct\n"]),
    # --- objref arrays and maps
    *[(f"objref {t}", [objref(f"objref {t} o")]) for t in [
        "O2", "O2[]", "O2{int32}", "O2{string}", "O2[]{int32}", "O2[]{string}", "O2[]{list}",
        "O2[]{generator}", "O2{list}", "O2{generator}", "O2[0]", "O2[0-]", "O2[3]", "O2[3-]", "O2[*]",
        "O2[3]{int32}", "O2[*]{int32}", "O2[2,2]", "O2[]{xx}", "varobject", "varobject[]",
        "varobject{string}", "varobject[]{int32}", "int32", "int32[]{int32}", "varvalue", "O2 [readonly]",
        "Missing[]{int32}", "O2[]{int32} [urgent]",
    ]],
    ("objref struct []{int32}", [H10 + "struct S\n    field int32 x\nend\nobject O\n    objref S[]{int32} o\nend\n"]),
    ("objref imported []{string}", [H10 + "import t.b\nobject O\n    objref t.b.P[]{string} o\nend\n",
                                    "service t.b\nstdver 0.10\nobject P\nend\n"]),
    ("objref via using []{int32}", [H10 + "import t.b\nusing t.b.P\nobject O\n    objref P[]{int32} o\nend\n",
                                    "service t.b\nstdver 0.10\nobject P\nend\n"]),
    ("objref implements same []{int32}", [OBJ2 + "object B\n    objref O2[]{int32} o\nend\n"
                                          "object O\n    implements B\n    objref O2[]{int32} o\nend\n"]),
    ("objref implements [] vs []{int32}", [OBJ2 + "object B\n    objref O2[] o\nend\n"
                                           "object O\n    implements B\n    objref O2[]{int32} o\nend\n"]),
    ("objref implements {int32} vs []{int32}", [OBJ2 + "object B\n    objref O2{int32} o\nend\n"
                                                "object O\n    implements B\n    objref O2[]{int32} o\nend\n"]),
    ("objref in struct", [OBJ2 + "struct S\n    objref O2 o\nend\n"]),
    # --- characters: byte-order mark and other non-ASCII (text semantics)
    ("BOM before service", [BOM + H10]),
    ("BOM before comment", [BOM + "# c\n" + H10]),
    ("BOM before blank line", [BOM + "\n" + H10]),
    ("BOM in comment", [H10 + "# x" + BOM + "\n"]),
    ("BOM in docstring", [H10 + "## x" + BOM + "\nstruct S\n    field int32 x\nend\n"]),
    ("BOM at end", [H10 + BOM]),
    ("BOM twice", [BOM + BOM + H10]),
    ("NBSP", ["service\u00a0t.a\nstdver 0.10\n"]),
    ("e-acute in comment", [H10 + "# caf\u00e9\n"]),
    ("form feed line", [H10 + "\f\n"]),
    ("vertical tab", [H10 + "\v\n"]),
    ("DEL", [H10 + "# \x7f\n"]),
    ("NUL", [H10 + "# \x00\n"]),
    ("NUL in continuation", [H10 + "struct S\n    field int32 \\\n\x00x\nend\n"]),
    ("CR only line ends", [H10.replace("\n", "\r")]),
    ("CRLF", [H10.replace("\n", "\r\n") + "struct S\r\n    field int32 x\r\nend\r\n"]),
    ("CRCRLF", [H10.replace("\n", "\r\r\n")]),
    ("CR inside a line", ["service t.a\nstdver\r0.10\n"]),
    ("leading blank lines", ["\n\n" + H10]),
    ("tabs", ["service\tt.a\nstdver\t0.10\nstruct\tS\n\tfield\tint32\tx\nend\n"]),
    ("continuation on last line", [H10 + "struct S\\"]),
    ("no trailing newline", ["service t.a\nstdver 0.10"]),
    ("empty text", [""]),
    ("comment only", ["# nothing\n"]),
    # --- other official quirks (robdef.md §20)
    ("property varvalue[]", [H10 + "object O\n    property varvalue[] v\nend\n"]),
    ("property object", [H10 + "object O\n    property object v\nend\n"]),
    ("property varobject", [H10 + "object O\n    property varobject v\nend\n"]),
    ("memory double{list}", [H10 + "object O\n    memory double{list} m\nend\n"]),
    ("memory double[]{int32}", [H10 + "object O\n    memory double[]{int32} m\nend\n"]),
    ("parameter name 1a", [H10 + "object O\n    function void f(double 1a, int32 _b)\nend\n"]),
    ("parameter name end", [H10 + "object O\n    function void f(string end)\nend\n"]),
    ("self-qualified type", [H10 + "struct S\n    field int32 x\nend\nobject O\n    property t.a.S s\nend\n"]),
    ("field double[0]", [H10 + "struct S\n    field double[0] x\nend\n"]),
    ("field double[0-]", [H10 + "struct S\n    field double[0-] x\nend\n"]),
    ("pod double[0]", [H10 + "pod P\n    field double[0] x\nend\n"]),
    ("empty namedarray", [H10 + "namedarray N\nend\n"]),
    ("empty struct", [H10 + "struct S\nend\n"]),
    ("namedarray double[2,2]", [H10 + "namedarray N\n    field double[2,2] x\nend\n"]),
    ("modifiers below 0.9", ["service t.a\noption version 0.8\nobject O\n    property double x [readonly]\nend\n"]),
    ("unknown modifier", [H10 + "object O\n    property double x [foo(1, bar)]\nend\n"]),
    ("blank inside modifier brackets", [H10 + "object O\n    property double x [ readonly]\nend\n"]),
    ("enum value end", [H10 + "enum E\n    a = 1, end\nend\n"]),
    ("enum end enum stdver 0.9", [H09 + "enum E\n    a = 1\nend enum\n"]),
    ("name rrate", [H10 + "struct rrate\n    field int32 x\nend\n"]),
    ("name get_x", [H10 + "object O\n    property int32 get_x\nend\n"]),
    ("name x_", [H10 + "object O\n    property int32 x_\nend\n"]),
    ("service name rr.x", ["service rr.x\nstdver 0.10\n"]),
    ("service name x.rr", ["service x.rr\nstdver 0.10\n"]),
    ("duplicate import", [H10 + "import t.b\nimport t.b\n", "service t.b\nstdver 0.10\n"]),
    ("import higher stdver", ["service t.a\nstdver 0.9\nimport t.b\n", "service t.b\nstdver 0.10\n"]),
    ("import without version", ["service t.a\nstdver 0.10\nimport t.b\n", "service t.b\n"]),
    ("using as alias", [H10 + "import t.b\nusing t.b.P as Q\nobject O\n    objref Q q\nend\n",
                        "service t.b\nstdver 0.10\nobject P\nend\n"]),
    ("using  as (two blanks)", [H10 + "import t.b\nusing t.b.P as  Q\n", "service t.b\nstdver 0.10\nobject P\nend\n"]),
    ("struct constant", [H10 + "constant int32 a 1\nconstant struct s {x: a}\n"]),
    ("struct constant recursive", [H10 + "constant struct s {x: s}\n"]),
    ("generator without generator", [H10 + "object O\n    function int32{generator} f()\n    function void g(int32{generator} x)\nend\n"]),
    ("modifier args with blank before comma", [H10 + "object O\n    property double x [foo(1 ,2)]\nend\n"]),
    ("modifier args with blank after paren", [H10 + "object O\n    property double x [foo( 1)]\nend\n"]),
    ("const string{list}", [const("string{list}", '"a"')]),
    ("const string{int32}", [const("string{int32}", '"a"')]),
    ("const string[]", [const("string[]", '"a"')]),
    ("const struct{list}", [H10 + "constant int32 a 1\nconstant struct{list} s {x: a}\n"]),
    ("const struct[]", [H10 + "constant int32 a 1\nconstant struct[] s {x: a}\n"]),
    ("const double{list}", [const("double{list}", "{1}")]),
    ("option alone", [HNONE + "option\n"]),
    ("option blank", [HNONE + "option \n"]),
    ("array size 2^31", [H10 + "struct S\n    field double[2147483648] x\nend\n"]),
]

# Files (bytes) read as files: the official ReadServiceDefinitionFile (utf-8-sig: one leading BOM is
# dropped) against `rr-robdef check` (strips one leading BOM, robdef.md §1.1). Needs --rr-robdef.
H10B = H10.encode()
FILE_CASES = [
    ("file with BOM", b"\xef\xbb\xbf" + H10B),
    ("file with BOM and CRLF", b"\xef\xbb\xbf" + H10B.replace(b"\n", b"\r\n")),
    ("file with two BOMs", b"\xef\xbb\xbf\xef\xbb\xbf" + H10B),
    ("file with BOM after a blank line", b"\n\xef\xbb\xbf" + H10B),
    ("file with BOM in a comment", H10B + b"# \xef\xbb\xbf\n"),
    ("file in UTF-16 with BOM", b"\xff\xfe" + H10.encode("utf-16-le")),
    ("file with invalid UTF-8", H10B + b"# \xff\n"),
    ("file with Latin-1 comment", H10B + b"# caf\xe9\n"),
    ("file without BOM", H10B),
]


def official_file_verdict(RR, path):
    from RobotRaconteur.RobotRaconteurPythonUtil import ReadServiceDefinitionFile
    try:
        text = ReadServiceDefinitionFile(path)
    except Exception as e:  # noqa: BLE001 (a file the official reader cannot decode is rejected)
        return "parse", "%s: %s" % (type(e).__name__, e), ""
    return official_verdict(RR, [text])


def official_verdict(RR, texts):
    """('parse'|'verify'|'accept', message, note)."""
    defs = []
    for t in texts:
        d = RR.ServiceDefinition()
        try:
            d.FromString(t)
        except Exception as e:  # noqa: BLE001 (any official error is a verdict)
            return "parse", str(e).splitlines()[0], ""
        defs.append(d)
    node = RR.RobotRaconteurNode()
    node.Init()
    try:
        node.RegisterServiceTypes(defs)
    except Exception as e:  # noqa: BLE001
        msg = str(e).splitlines()[0]
        printing_errors = []
        for d in defs:
            try:
                d.ToString()
            except Exception as e2:  # noqa: BLE001
                printing_errors.append(str(e2).splitlines()[0])
        if msg in printing_errors:
            return "accept", "", "official ToString fails: " + msg
        return "verify", msg, ""
    finally:
        node.Shutdown()
    return "accept", "", ""


def transitive_imports(name, by_service):
    seen, todo = [], [name]
    while todo:
        n = todo.pop()
        if n in seen or n not in by_service:
            continue
        seen.append(n)
        todo.extend(re.findall(r"^[ \t]*import[ \t]+([\w.]+)", by_service[n][1], re.M))
    return seen


def read_text(path):
    # Files as the official Python library reads them (ReadServiceDefinitionFile: utf-8-sig).
    with open(path, "r", encoding="utf-8-sig", newline="") as f:
        return f.read()


def standard_cases(standard_dir, extra):
    cases = []
    g1 = sorted(os.path.join(standard_dir, "group1", f) for f in os.listdir(os.path.join(standard_dir, "group1"))
                if f.endswith(".robdef"))
    g2 = sorted(os.path.join(standard_dir, "group2", f) for f in os.listdir(os.path.join(standard_dir, "group2"))
                if f.endswith(".robdef"))
    by_service = {}
    for p in g1:
        text = read_text(p)
        m = re.search(r"^[ \t]*service[ \t]+([\w.]+)", text, re.M)
        by_service[m.group(1)] = (p, text)
    for name, (p, _) in sorted(by_service.items()):
        names = transitive_imports(name, by_service)
        cases.append(("std " + os.path.basename(p), [by_service[n][1] for n in names]))
    all_g1 = [by_service[n][1] for n in sorted(by_service)]
    cases.append(("std group1 together", all_g1))
    for p in g2:
        cases.append(("std group1 + " + os.path.basename(p), all_g1 + [read_text(p)]))
    cases.append(("std group1 + both group2", all_g1 + [read_text(p) for p in g2]))
    for p in extra:
        cases.append(("file " + os.path.basename(p), [read_text(p)]))
    return cases


def folder_name(i, name):
    return "%03d_%s" % (i, re.sub(r"[^A-Za-z0-9_.+-]+", "_", name)[:60])


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--verdicts", required=True, help="rr_robdef_verdicts executable")
    ap.add_argument("--cases", choices=["edge", "standard"], default="edge")
    ap.add_argument("--standard", help="robdef-standard folder (group1/, group2/)")
    ap.add_argument("--extra", nargs="*", default=[], help="more robdef files, one case each")
    ap.add_argument("--rr-robdef", help="rr-robdef executable: also compare reading files (byte-order marks)")
    ap.add_argument("--keep", help="write the case folders here instead of a temporary folder")
    ap.add_argument("--verbose", action="store_true")
    args = ap.parse_args()

    try:
        import RobotRaconteur as RR
    except ImportError as e:
        print("SKIP: the official package is not installed (%s); run ./scripts/setup.sh" % e)
        return 77

    if args.cases == "edge":
        cases = EDGE_CASES
    else:
        if not args.standard or not os.path.isdir(os.path.join(args.standard, "group1")):
            print("SKIP: standard robdefs not found at %s (RR_SHARED_DIR)" % args.standard)
            return 77
        extra = [p for p in args.extra if os.path.isfile(p)]
        cases = standard_cases(args.standard, extra)
    names = [n for n, _ in cases]
    assert len(set(names)) == len(names), "case names must be unique"

    root = args.keep or tempfile.mkdtemp(prefix="rr_robdef_agreement_")
    os.makedirs(root, exist_ok=True)
    try:
        dirs = []
        for i, (name, texts) in enumerate(cases):
            d = os.path.join(root, folder_name(i, name))
            shutil.rmtree(d, ignore_errors=True)
            os.makedirs(d)
            for k, t in enumerate(texts):
                with open(os.path.join(d, "%02d.robdef" % k), "wb") as f:
                    f.write(t.encode("utf-8"))
            dirs.append(d)
        proc = subprocess.run([args.verdicts] + dirs, capture_output=True, text=True, timeout=300)
        if proc.returncode != 0:
            print("rr_robdef_verdicts failed (%d):\n%s" % (proc.returncode, proc.stderr))
            return 1
        ours = {}
        for line in proc.stdout.splitlines():
            parts = line.split("\t")
            ours[parts[0]] = (parts[1], parts[2] if len(parts) > 2 else "")

        disagreements = 0
        stage_differs = []
        counts = {"accept": 0, "parse": 0, "verify": 0}
        for (name, texts), d in zip(cases, dirs):
            off, off_msg, note = official_verdict(RR, texts)
            our, our_msg = ours.get(d, ("missing", "no verdict printed"))
            counts[off] = counts.get(off, 0) + 1
            problems = []
            if (our == "accept") != (off == "accept"):
                problems.append("official: %s %s | ours: %s %s" % (off, off_msg, our, our_msg))
            elif our != off:
                # Both reject, at different stages (e.g. an enum value named `end`: a parse error
                # here, so that canonical text never ends a block early; a reserved name there).
                stage_differs.append("%s (official: %s %s | ours: %s %s)" % (name, off, off_msg, our, our_msg))
            if our == "accept":
                canon = [open(os.path.join(d, "%02d.robdef.canonical" % k), encoding="utf-8").read()
                         for k in range(len(texts))]
                c_off, c_msg, _ = official_verdict(RR, canon)
                if c_off != off:
                    problems.append("our canonical text gets official %s %s (original: %s)" % (c_off, c_msg, off))
            if problems:
                disagreements += 1
                print("DISAGREE %s\n    %s" % (name, "\n    ".join(problems)))
            elif args.verbose:
                print("agree    %-45s %-6s %s%s" % (name, off, off_msg or our_msg, ("  [" + note + "]") if note else ""))
        if args.cases == "edge" and args.rr_robdef:
            for i, (name, data) in enumerate(FILE_CASES):
                d = os.path.join(root, folder_name(len(cases) + i, name))
                shutil.rmtree(d, ignore_errors=True)
                os.makedirs(d)
                path = os.path.join(d, "t.robdef")
                with open(path, "wb") as f:
                    f.write(data)
                off, off_msg, _ = official_file_verdict(RR, path)
                p = subprocess.run([args.rr_robdef, "check", path], capture_output=True, text=True, timeout=60)
                our = {0: "accept", 1: "reject"}.get(p.returncode, "failed (%d)" % p.returncode)
                counts[off] = counts.get(off, 0) + 1
                if (our == "accept") != (off == "accept") or our.startswith("failed"):
                    disagreements += 1
                    print("DISAGREE %s\n    official: %s %s | ours (rr-robdef check): %s %s"
                          % (name, off, off_msg, our, p.stdout.strip() + p.stderr.strip()))
                elif args.verbose:
                    print("agree    %-45s %-6s %s" % (name, off, off_msg))
            ncases = len(cases) + len(FILE_CASES)
        else:
            ncases = len(cases)
        for s in stage_differs:
            print("both reject, at different stages: " + s)
        print("robdef agreement (%s): %d cases (official: %d accept, %d parse errors, %d verify errors), "
              "%d disagreements" % (args.cases, ncases, counts["accept"], counts["parse"], counts["verify"],
                                    disagreements))
        return 1 if disagreements else 0
    finally:
        if not args.keep:
            shutil.rmtree(root, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
