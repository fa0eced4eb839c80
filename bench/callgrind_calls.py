#!/usr/bin/env python3
"""Counts the calls to given functions recorded in a callgrind output file (the `calls=` lines).

Usage: callgrind_calls.py FILE NAME...   -> one line per NAME: "NAME CALLS"
Names are matched exactly against callgrind's function names (e.g. malloc, free).
"""
import re
import sys


def main():
    path, names = sys.argv[1], sys.argv[2:]
    ids, counts, callee = {}, {n: 0 for n in names}, None
    ref = re.compile(r"^c?fn=\((\d+)\)(?: (.*))?$")
    with open(path, errors="replace") as f:
        for line in f:
            m = ref.match(line.rstrip("\n"))
            if m:
                if m.group(2) is not None:
                    ids[m.group(1)] = m.group(2)
                callee = ids.get(m.group(1)) if line.startswith("cfn=") else None
            elif line.startswith("calls=") and callee in counts:
                counts[callee] += int(line[6:].split()[0])
                callee = None
    for n in names:
        print(n, counts[n])


if __name__ == "__main__":
    main()
