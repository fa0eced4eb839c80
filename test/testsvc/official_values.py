#!/usr/bin/env python3
"""Makes rr-test-service's official values file from a checkout of the official repository.

The official test services return and expect literal tables (TestService1) and walk two constant
tables (the TestService3 recipes). They are data of robotraconteur/robotraconteur (Apache 2.0), not of
this project: this script reads them from a checkout at run time and writes them to a file outside the
repository, in the format of test/testsvc/test_values.hpp. Nothing it writes is committed.

    .venv/bin/python test/testsvc/official_values.py --repo /path/to/robotraconteur -o /tmp/official-values.json
    build/debug/test/testsvc/rr-test-service --official-values /tmp/official-values.json

How: the official Python test services (test/python/RobotRaconteurTest/ServiceTest*.py) are imported
and each property getter is called; a setter whose body is one comparison of the value with an
expression (`assert value == X`, `ca(value, X)`, `assert_allclose(value, X)` or `(X, value)`) gives
X as the value a set must send. Other setters are listed as unchecked (rr-test-service then accepts any
value of the type for them, as it says in docs/native-service.md). Needs numpy and the official
package (the project's .venv) and pytest (the official modules import it; any installed copy).
"""

import argparse
import ast
import glob
import inspect
import json
import os
import sys
import textwrap

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import testsvc_values as tv  # noqa: E402

TS1 = "com.robotraconteur.testing.TestService1"
TS3 = "com.robotraconteur.testing.TestService3"
# Members whose behaviour rr-test-service implements itself (recipes, special cases), not tables.
NOT_TABLES = {
    TS1 + ".testroot": {"i32_huge", "errtest", "nulltest"},
    TS3 + ".testroot3": {"testenum1_prop", "testpod1_prop", "teststruct3_prop", "testnamedarray1", "testnamedarray2",
                         "testnamedarray3", "testnamedarray4", "testnamedarray5"},
}


class FakeContext:
    def __init__(self, node):
        self._node = node

    def GetNode(self):
        return self._node


def setter_expression(prop):
    """The expression a setter compares the whole value with, or None."""
    try:
        src = textwrap.dedent(inspect.getsource(prop.fset))
    except (OSError, TypeError):
        return None
    fn = ast.parse(src).body[0]
    body = [s for s in fn.body if not isinstance(s, ast.Pass)]
    if len(body) != 1:
        return None
    s = body[0]
    if isinstance(s, ast.Assert) and isinstance(s.test, ast.Compare) and len(s.test.ops) == 1 \
            and isinstance(s.test.ops[0], ast.Eq) and isinstance(s.test.left, ast.Name) and s.test.left.id == "value":
        return s.test.comparators[0]
    if isinstance(s, ast.Expr) and isinstance(s.value, ast.Call) and len(s.value.args) == 2:
        f = s.value.func
        name = f.id if isinstance(f, ast.Name) else f.attr if isinstance(f, ast.Attribute) else ""
        if name in ("ca", "assert_allclose"):
            a, b = s.value.args
            if isinstance(a, ast.Name) and a.id == "value":
                return b
            if isinstance(b, ast.Name) and b.id == "value":
                return a
    return None


def extract_object(types, impl, module, object_type, log):
    props = {}
    for kind, name, t, _, mods in types.members(object_type):
        if kind != "property" or name in NOT_TABLES.get(object_type, ()):
            continue
        prop = getattr(type(impl), name, None)
        if not isinstance(prop, property):
            log.append("%s.%s: no official implementation (LFSR value)" % (object_type, name))
            continue
        entry = {}
        try:
            entry["get"] = tv.to_json(types, getattr(impl, name), t)
        except Exception as e:  # the official getter fails: leave it to rr-test-service
            log.append("%s.%s: get fails officially (%s): LFSR value" % (object_type, name, type(e).__name__))
            continue
        expr = setter_expression(prop) if prop.fset else None
        if expr is not None:
            value = eval(compile(ast.Expression(expr), "<setter>", "eval"), vars(module))
            entry["set"] = tv.to_json(types, value, t)
        else:
            log.append("%s.%s: set unchecked (the official setter is not one comparison)" % (object_type, name))
        props[name] = entry
    return props


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repo", required=True, help="checkout of robotraconteur/robotraconteur")
    ap.add_argument("-o", "--output", required=True)
    ap.add_argument("--robdef-dir", default=None, help="the test definitions (default: the checkout's test/robdef)")
    args = ap.parse_args()

    pydir = os.path.join(args.repo, "test", "python")
    robdef_dir = args.robdef_dir or os.path.join(args.repo, "test", "robdef")
    sys.path.insert(0, pydir)
    import RobotRaconteur as RR
    from RobotRaconteurTest import ServiceTest, ServiceTest2

    texts = [open(f).read() for f in sorted(glob.glob(os.path.join(robdef_dir, "com.robotraconteur.testing.TestService*.robdef")))]
    types = tv.Types(texts)
    node = RR.RobotRaconteurNode()
    node.Init()
    log = []
    try:
        node.RegisterServiceTypes(texts)
        root1 = ServiceTest.testroot_impl(None)
        root1.RRServiceObjectInit(FakeContext(node), "RobotRaconteurTestService")
        root3 = ServiceTest2.testroot3_impl()
        root3.RRServiceObjectInit(FakeContext(node), "RobotRaconteurTestService2")
        objects = {
            TS1 + ".testroot": {"properties": extract_object(types, root1, ServiceTest, TS1 + ".testroot", log),
                                "memories": {"m1": tv.to_json(types, root1.m1.memory, tv.T("double", tv.ARRAY))}},
            TS3 + ".testroot3": {"properties": extract_object(types, root3, ServiceTest2, TS3 + ".testroot3", log)},
        }
        gen = ServiceTest2.ServiceTest2_test_sequence_gen
        doc = {
            "format": "rr-testsvc-official-values 1",
            "source": "robotraconteur/robotraconteur test/python (%s)" % os.path.abspath(args.repo),
            "objects": objects,
            "sequence": {"doubles": list(gen.double_constants), "uint32s": list(gen.uint32_constants)},
        }
    finally:
        node.Shutdown()
    with open(args.output, "w") as f:
        json.dump(doc, f)
    for line in log:
        print(line)
    n = sum(len(o["properties"]) for o in objects.values())
    print("wrote %s: %d properties, %d sequence numbers" % (args.output, n,
          len(doc["sequence"]["doubles"]) + len(doc["sequence"]["uint32s"])))


if __name__ == "__main__":
    main()
