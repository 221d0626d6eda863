"""The `LABEL=PATH` arguments the chart scripts take, one per table to draw."""

import sys


def labelled_paths(argv, usage, what):
    """[(label, path)] of `argv`, each `LABEL=PATH`; exits naming the first that is not, or with
    `usage` when there is none. `what` names the path in the message (`RUNS.csv`)."""
    pairs = []
    for arg in argv:
        label, sep, path = arg.partition("=")
        if not sep or not label or not path:
            sys.exit(f"expected LABEL={what}, got {arg!r}")
        pairs.append((label, path))
    if not pairs:
        sys.exit(usage)
    return pairs
