#!/usr/bin/env python3
"""Functions longer than a limit (default 120 lines), longest first.

    scripts/long_functions.py [--max N] [DIR ...]      (default: src core/src)

Counts from a function's `fn` line to its closing brace by brace depth, with
comments, string and character literals left out; a rough count of the
layout rule in docs/architecture.md, not a parser.
"""
import os
import re
import sys

LITERALS = re.compile(r'"(?:\\.|[^"\\])*"|b?\'(?:\\.|[^\'\\])\'')
FN = re.compile(r'\s*(pub(\([^)]*\))?\s+)?(const\s+)?(async\s+)?(unsafe\s+)?fn\s+(\w+)')


def code(line):
    return LITERALS.sub('""', line).split('//')[0]


def long_functions(path, limit):
    lines = [code(l) for l in open(path, encoding='utf-8').read().split('\n')]
    out = []
    for i, line in enumerate(lines):
        m = FN.match(line)
        if not m:
            continue
        depth, started = 0, False
        for j in range(i, len(lines)):
            if ';' in lines[j] and not started and '{' not in lines[j]:
                break
            depth += lines[j].count('{') - lines[j].count('}')
            started = started or '{' in lines[j]
            if started and depth <= 0:
                n = j - i + 1
                if n > limit:
                    out.append((n, path, m.group(6)))
                break
    return out


def main(argv):
    limit = 120
    if argv[:1] == ['--max']:
        limit, argv = int(argv[1]), argv[2:]
    found = []
    for root in argv or ['src', 'core/src']:
        for dirpath, _, files in os.walk(root):
            for f in files:
                if f.endswith('.rs'):
                    found += long_functions(os.path.join(dirpath, f), limit)
    for n, path, name in sorted(found, reverse=True):
        print(n, path, name)
    print(f'{len(found)} functions over {limit} lines')


if __name__ == '__main__':
    main(sys.argv[1:])
