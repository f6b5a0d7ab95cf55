"""The checks of the regression scripts: each prints one line, 'ok' or 'FAILED', with its
name and the figures behind it; `summary` prints the closing line 'N passed, M failed' and
gives the exit code (0 only when every check passed and at least one ran)."""

FAILED = []
PASSED = []


def check(name, ok, detail=""):
    """Record check `name` (ok is its outcome) and print it with `detail`; returns ok."""
    ok = bool(ok)
    print(f"{'ok    ' if ok else 'FAILED'} {name}: {detail}")
    (PASSED if ok else FAILED).append(name)
    return ok


def summary():
    """Print the failed checks and the closing line; the script's exit code."""
    if FAILED:
        print("failed:", ", ".join(FAILED))
    print(f"{len(PASSED)} passed, {len(FAILED)} failed")
    return 1 if FAILED or not PASSED else 0
