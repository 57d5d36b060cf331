"""The parser process of :mod:`holoradar.io.readers` (``python -m holoradar.io._parse_server``).

Reads requests ``["reader name", "path"]`` (one JSON line each) on stdin and
answers each with 8 bytes of length (big-endian) then ``b"K"`` + the arrays as
.npz bytes, or ``b"E"`` + an error message. A parser that crashes takes only
this process down; the caller reports the file as damaged and starts a new one.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path


def serve() -> None:  # pragma: no cover - runs in the parser process
    from holoradar.io import readers

    allowed = {f.__name__: f for f in readers._ISOLATED}
    out = sys.stdout.buffer
    for line in sys.stdin.buffer:
        try:
            name, path = json.loads(line)
            reader = allowed[name]
            answer = b"K" + readers.pack(reader(Path(path)))
        except ValueError as exc:
            answer = b"E" + str(exc).encode("utf-8", "replace")
        except Exception as exc:  # any parser failure becomes the file's error
            p = Path(str(path)) if "path" in locals() else Path("file")
            answer = b"E" + (f"{p.name} is not a readable {p.suffix} file "
                             f"({type(exc).__name__}: {exc})").encode("utf-8", "replace")
        out.write(len(answer).to_bytes(8, "big"))
        out.write(answer)
        out.flush()


if __name__ == "__main__":
    serve()
