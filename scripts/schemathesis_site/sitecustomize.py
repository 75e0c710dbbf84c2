"""Loaded by the Schemathesis run of scripts/schemathesis.sh (PYTHONPATH).

CPython 3.11 keeps the AST constructor's recursion depth in state shared by
every thread, so two threads inside `ast.parse` at once can fail with
"SystemError: AST constructor recursion depth mismatch" (python/cpython
gh-106905). Hypothesis parses lambdas' sources to describe strategies, and
Schemathesis's workers are threads: a run once ended with that error, inside
the tool, before any request. One lock around `ast.parse` keeps the parses one
at a time; nothing else changes.
"""

import ast
import threading

_LOCK = threading.RLock()
_PARSE = ast.parse


def _parse_one_at_a_time(*args, **kwargs):
    with _LOCK:
        return _PARSE(*args, **kwargs)


ast.parse = _parse_one_at_a_time
