"""One side of an interleaved run (:mod:`benchmarks.speed.interleave`): a fresh interpreter,
its own ``impact_balance`` first on ``PYTHONPATH``, driven by JSON lines on stdin.

Requests: ``{"cmd": "setup", "job": "module:function", "params": {...}}`` (builds the job:
``function(params)``; replies its ``info``), ``{"cmd": "block", "k": k, "n": blocks}`` (replies
``job.block(k, blocks)``). Every reply is one JSON line on the original stdout; a failure
replies ``{"error": "..."}``. Anything the job prints goes to stderr. End of input ends it.

    python -m benchmarks.speed.worker    # from the repository root, as the driver starts it
"""

from __future__ import annotations

import importlib
import json
import sys
import traceback
from typing import Any

__all__ = ["main"]


def _load(job: str, params: dict[str, Any]) -> Any:
    module, _, function = job.partition(":")
    return getattr(importlib.import_module(module), function)(params)


def main() -> int:
    channel = sys.stdout
    sys.stdout = sys.stderr  # the job's prints must not corrupt the replies
    state: Any = None
    for line in sys.stdin:
        if not line.strip():
            continue
        try:
            request = json.loads(line)
            if request["cmd"] == "setup":
                state = _load(request["job"], request.get("params", {}))
                import impact_balance

                reply = {"info": dict(state.info), "impact_balance": impact_balance.__file__}
            elif request["cmd"] == "block":
                if state is None:
                    raise RuntimeError("block before setup")
                reply = state.block(int(request["k"]), int(request["n"]))
            else:
                raise ValueError(f"unknown cmd {request['cmd']!r}")
        except Exception as exc:  # reported to the driver, which names the side
            traceback.print_exc()
            reply = {"error": f"{type(exc).__name__}: {exc}"}
        channel.write(json.dumps(reply, default=float) + "\n")
        channel.flush()
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main())
    except KeyboardInterrupt:  # Ctrl-C reaches the whole process group: the driver reports it
        sys.exit(130)
