"""`python -m grader fixtures`: regenerate fixtures/ from the reference."""
from __future__ import annotations

import argparse
import time

HELP = "regenerate fixtures/ (renders, sweep colours, manifest) from the reference"


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--check", action="store_true", help="only report whether fixtures/ is stale (exit 1 if so)")


def run(args) -> int:
    from ..grading import fixtures
    if args.check:
        try:
            fixtures.check_stale()
        except fixtures.StaleFixtures as e:
            print(e)
            return 1
        print("fixtures are up to date")
        for warning in fixtures.environment_warnings():   # not stale, but made elsewhere: say so
            print(f"note: {warning}")
        return 0
    t0 = time.monotonic()
    manifest = fixtures.generate()
    size = sum((fixtures.PROJECT_ROOT / f).stat().st_size for f in manifest["files"])
    print(f"wrote {len(manifest['files'])} fixture files ({size / 1e6:.2f} MB) and fixtures/manifest.json "
          f"in {time.monotonic() - t0:.1f} s")
    env = manifest["environment"]
    print("recorded: " + ", ".join(f"{k} {v}" for k, v in env["libraries"].items())
          + "; " + "; ".join(env["compilers"].values()))
    return 0
