"""Write ``openapi/openapi.json`` from the app, or check that the committed file is current.

Usage::

    python scripts/gen_openapi.py           # (re)write the file
    python scripts/gen_openapi.py --check   # exit 1 if the file differs from the app's spec
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from service.main import app

SPEC_PATH = Path(__file__).resolve().parents[1] / "openapi" / "openapi.json"


def render() -> str:
    """The app's OpenAPI document: sorted keys, 2-space indent, trailing newline."""
    return json.dumps(app.openapi(), indent=2, sort_keys=True) + "\n"


def main(argv: list[str] | None = None) -> int:
    """Write or check the spec; return the exit status."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--check", action="store_true", help="exit 1 if the committed spec is out of date"
    )
    args = parser.parse_args(argv)
    text = render()
    if args.check:
        current = SPEC_PATH.read_text() if SPEC_PATH.exists() else ""
        if current != text:
            print(f"{SPEC_PATH} is out of date: run python scripts/gen_openapi.py", file=sys.stderr)
            return 1
        print(f"{SPEC_PATH} is up to date")
        return 0
    SPEC_PATH.parent.mkdir(exist_ok=True)
    SPEC_PATH.write_text(text)
    print(f"wrote {SPEC_PATH}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
