#!/usr/bin/env python3
"""Our LFSR (testsvc_values.Lfsr, the same rules as lfsr.cpp) against the official one, by hand.

The official Python package on PyPI does not ship the test generator; the official repository does
(test/python/RobotRaconteurTest/lfsr.py). Given a checkout, this draws every value kind for many seeds
and keys from both and compares them number by number (doubles and floats by their bits). CI checks
lfsr.cpp against a few of these numbers (lfsr_test.cpp) and testsvc_checks.py checks that lfsr.cpp
(in rr-test-service) and testsvc_values.py draw the same values; this closes the chain.

    .venv/bin/python test/testsvc/lfsr_official_compare.py --repo /path/to/robotraconteur
Exit 0: identical; 1: a difference (printed); 77: no checkout given or found.
"""

import argparse
import importlib.util
import math
import os
import struct
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from testsvc_values import Lfsr  # noqa: E402

KINDS = ["int8", "uint8", "int16", "uint16", "int32", "uint32", "int64", "uint64", "float", "double", "bool",
         "cfloat", "cdouble", "char"]


def bits(x):
    if isinstance(x, complex):
        return (bits(x.real), bits(x.imag))
    if isinstance(x, float):
        return struct.unpack("<Q", struct.pack("<d", x))[0]
    return x


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repo", default=os.environ.get("RR_OFFICIAL_REPO"))
    args = ap.parse_args()
    path = args.repo and os.path.join(args.repo, "test", "python", "RobotRaconteurTest", "lfsr.py")
    if not path or not os.path.exists(path):
        print("SKIP: no official checkout (--repo or RR_OFFICIAL_REPO)")
        return 77
    spec = importlib.util.spec_from_file_location("official_lfsr", path)
    official = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(official)

    keys = ["", "x", "Hello World!", "d1_get", "d1_set", "struct1_get", "sequence_doubles", "m1_init",
            "multidimarray_test_double", "a key with spaces and ~!@#"]
    seeds = [0, 1, 55, 1234, 35913226, 2 ** 31, 2 ** 32 - 1]
    compared = 0
    for seed in seeds:
        for key in keys:
            a, b = Lfsr(seed, key), official.LFSRSeqGen(seed, key)
            if a.state != b.lfsr:
                print("init differs: seed %d key %r: %d vs %d" % (seed, key, a.state, b.lfsr))
                return 1
            for i in range(200):
                kind = KINDS[i % len(KINDS)]
                ours = getattr(a, "next_" + kind)()
                theirs = getattr(b, "next_" + kind)()
                if kind == "float":
                    ours, theirs = struct.pack("<f", ours), struct.pack("<f", theirs)
                elif kind in ("cfloat", "cdouble"):
                    # The official Python draws a complex as `re + im * 1j`, which is re + im·0 in the real
                    # part: NaN when im is infinite or NaN, +0.0 for re = -0.0. Its C generator (test/lfsr)
                    # and ours keep both parts as drawn, so the real part is compared as that sum.
                    fmt = "<f" if kind == "cfloat" else "<d"
                    same_imag = struct.pack(fmt, ours.imag) == struct.pack(fmt, theirs.imag)
                    if math.isfinite(theirs.imag):
                        re = ours.real + theirs.imag * 0.0
                        same_real = (math.isnan(re) and math.isnan(theirs.real)) or re == theirs.real
                    else:
                        same_real = math.isnan(theirs.real)
                    ours, theirs = (same_imag and same_real), True
                else:
                    ours, theirs = bits(ours), bits(theirs)
                if ours != theirs:
                    print("differs: seed %d key %r draw %d (%s): %r vs %r" % (seed, key, i, kind, ours, theirs))
                    return 1
                compared += 1
            for m in (3, 17, 32, 100):
                if a.next_len(m) != b.next_len(m):
                    print("next_len(%d) differs: seed %d key %r" % (m, seed, key))
                    return 1
            if a.next_dist(1, 4) != b.next_dist(1, 4) or a.next_string(12) != b.next_string(12):
                print("next_dist / next_string differ: seed %d key %r" % (seed, key))
                return 1
            compared += 6
    print("identical: %d values over %d seeds and %d keys" % (compared, len(seeds), len(keys)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
