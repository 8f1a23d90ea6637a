"""The contact-aware rates in a process of their own, off the control tick.

``Governor(..., contact_aware=ContactAwareOptions(asynchronous=True))``: the contact-aware
impact's jump rates (:mod:`.support`) are computed by a worker process while the governor keeps
ticking with the last rates it received. Each tick the governor collects a finished answer if
there is one (a pipe poll that never waits) and, when the worker is idle, sends it the current
posture. The worker continues from its own last answer, which is the one the governor uses (it
adopts every answer it receives), so a request is the posture only. The rates in use are
therefore those of a posture one recomputation old (their age in postures is
:attr:`~.support.ContactAwareAnswer.age`).

Processes. The worker is a fresh interpreter (``python -m impact_balance.governor.worker``)
joined by a socket pair; it runs at the lowest scheduling priority (nice 19: it computes on a
core the control loop leaves free and never preempts it), builds its own robot from the
scenario once and answers until the governor closes it (:meth:`Governor.close`, the end of a
``with`` block, or the governor's collection). On a machine whose every core is busy it gets
little time and its rates age. POSIX only (the worker inherits one end of a socket pair).

Failures are :class:`WorkerError` (a :class:`~impact_balance.exceptions.GovernorError`)
naming ``contact_aware_async``: a worker that cannot start, does not answer in
:data:`START_TIMEOUT`, fails on a posture (raised on the governor's next tick), or ends (killed,
crashed: noticed on the next tick, whether the posture changed or not, and raised on every
tick after). The governor never writes to the worker with SIGPIPE armed: a dead worker is an
error, not a signal that ends the controller.
"""

from __future__ import annotations

import os
import pickle
import select
import socket
import struct
import subprocess
import sys
import weakref
from multiprocessing.connection import Connection
from typing import TYPE_CHECKING, Any

import numpy as np

from impact_balance.exceptions import GovernorError, ScenarioError
from impact_balance.governor.options import Starts
from impact_balance.governor.support import ContactAwareLimit, ContactAwareSolutions

if TYPE_CHECKING:
    from impact_balance.scenario import Scenario

__all__ = ["ContactAwareWorker", "WorkerError"]

#: Seconds to wait for the worker's start (a fresh interpreter, its imports and the robot, ~2 s).
START_TIMEOUT = 120.0
#: send() without SIGPIPE (Linux); elsewhere 0, and a dead worker raises BrokenPipeError only
#: where SIGPIPE is ignored (Python's default).
_NOSIGNAL = getattr(socket, "MSG_NOSIGNAL", 0)


class WorkerError(GovernorError):
    """The contact-aware worker process failed: it did not start, ended, or failed on a posture.

    A :class:`~impact_balance.exceptions.GovernorError` on ``contact_aware_async``; the
    command line exits 1 (a failure of the machine, not of the input).
    """

    exit_status = 1


def _send(sock: socket.socket, message: object) -> None:
    """``message`` in :class:`~multiprocessing.connection.Connection`'s framing, without SIGPIPE."""
    payload = pickle.dumps(message, protocol=pickle.HIGHEST_PROTOCOL)
    sock.sendall(struct.pack("!i", len(payload)) + payload, _NOSIGNAL)


def _serve(conn: Connection) -> None:
    """The worker's loop.

    First ``(scenario dict, source, starts)``, then ``(key, q)`` in and ``(key, solutions,
    error)`` out, each solve continuing the last answer; None or a closed pipe stops it.
    """
    from impact_balance.contacts.stance import Stance
    from impact_balance.scenario import scenario_from_dict

    raw, source, starts = conn.recv()
    # The lowest priority: woken by a request, the worker must not take the CPU from the
    # control loop that sent it (docs/studies/design-history.md). It runs on a free core.
    os.nice(19)
    try:
        scenario = scenario_from_dict(raw, source)
        robot = scenario.load_robot()
        # The governor's contacts: resolved at the scenario's stance, as analyze() does.
        contacts = tuple(c.spec for c in scenario.build_stance(robot).contacts)
        if scenario.impact is None:
            raise ScenarioError("impact", None, "the contact-aware worker needs an impact")
        limit = ContactAwareLimit(scenario.impact.spec(), 1, starts)
    except Exception as exc:
        conn.send(("ready", None, f"{type(exc).__name__}: {exc}"))
        return
    conn.send(("ready", None, None))
    last: ContactAwareSolutions | None = None  # the answer the governor uses: the next start
    while True:
        try:
            message = conn.recv()
        except (EOFError, OSError):  # the governor went away
            return
        if message is None:
            return
        key, q = message
        try:
            last = limit.solve(Stance(robot, np.asarray(q, dtype=float), contacts), last)
            conn.send((key, last, None))
        except Exception as exc:  # reported to the governor, which raises it on its next tick
            conn.send((key, None, f"{type(exc).__name__}: {exc}"))


def _stop(sock: socket.socket, conn: Connection, process: subprocess.Popen[bytes]) -> None:
    """Ask the worker to stop, then make sure it has (killed after a grace period)."""
    try:
        _send(sock, None)
    except (OSError, ValueError):
        pass
    try:
        process.wait(timeout=2.0)
    except subprocess.TimeoutExpired:
        process.kill()  # also ends a stopped (SIGSTOP) worker
        process.wait(timeout=2.0)
    conn.close()
    sock.close()


class ContactAwareWorker:
    """One worker process computing contact-aware rates for one governor (module docstring).

    Not thread-safe (its governor calls it under its lock).

    The worker is a fresh interpreter (``python -m impact_balance.governor.worker``) joined by a
    socket pair, not a :mod:`multiprocessing` child: a spawned child re-imports the user's main
    script, and a forked one inherits pinocchio's, numba's and BLAS's threads.
    """

    def __init__(self, scenario: Scenario, starts: Starts):
        parent, child = socket.socketpair()
        env = dict(os.environ)
        env["PYTHONPATH"] = os.pathsep.join(p for p in sys.path if p)  # the same impact_balance
        try:
            self._process = subprocess.Popen(
                [sys.executable, "-m", "impact_balance.governor.worker", str(child.fileno())],
                pass_fds=(child.fileno(),),
                stdin=subprocess.DEVNULL,
                stdout=subprocess.DEVNULL,
                stderr=subprocess.DEVNULL,
                env=env,
                close_fds=True,
            )
        except (
            OSError,
            ValueError,
        ) as exc:  # ValueError: no pass_fds (Windows); the option is POSIX-only
            parent.close()
            raise WorkerError(
                "contact_aware_async", None, f"could not start the worker ({exc})"
            ) from None
        finally:
            child.close()
        # Sent through the socket (MSG_NOSIGNAL), received through a Connection on its copy.
        self._sock = parent
        self._conn = Connection(os.dup(parent.fileno()))
        # A tick's check for an answer: select.poll is several times cheaper than
        # Connection.poll (docs/studies/design-history.md). A dead worker reports POLLHUP.
        self._poller = select.poll()
        self._poller.register(self._conn.fileno(), select.POLLIN)
        self._finalizer = weakref.finalize(self, _stop, self._sock, self._conn, self._process)
        self._busy = True  # until "ready"
        self._failure: WorkerError | None = None  # once the worker has ended: raised every call
        self.submitted: bytes | None = None
        self._write((scenario.model_dump(exclude_none=True), scenario.source, starts))
        if not self._conn.poll(START_TIMEOUT):
            self.close()
            raise WorkerError("contact_aware_async", None, "the worker process did not start")
        try:
            self._receive()
        except GovernorError:
            self.close()
            raise

    @property
    def pid(self) -> int:
        """The worker's process id."""
        return self._process.pid

    def _ended(self, how: str) -> WorkerError:
        """Record that the worker has ended (every later call raises it) and return the error."""
        code = self._process.poll()
        detail = f"{how}; exit status {code}" if code is not None else how
        self._failure = WorkerError(
            "contact_aware_async", self._process.pid, f"the worker process ended ({detail})"
        )
        self._busy = False
        return self._failure

    def _write(self, message: object) -> None:
        try:
            _send(self._sock, message)
        except OSError as exc:  # BrokenPipeError, ConnectionResetError: the worker is gone
            raise self._ended(type(exc).__name__) from None

    def warm_up(self, q: np.ndarray) -> ContactAwareSolutions:
        """Solve once at ``q`` and wait, returning the answer.

        The worker's first solve loads its compiled code: the governor pays it at
        construction (and takes the answer as its first rates) rather than in its first ticks.

        Args:
            q: The configuration (nq, pinocchio's order).

        Returns:
            The contact-aware solutions at ``q``.

        Raises:
            GovernorError: The worker did not answer within :data:`START_TIMEOUT` s.
        """
        try:
            self.submit(b"warm-up", q)
            solutions = self.wait(START_TIMEOUT)
        except GovernorError:
            self.close()
            raise
        if solutions is None:
            self.close()
            raise WorkerError("contact_aware_async", None, "the worker did not answer")
        return solutions

    def _receive(self) -> tuple[Any, ContactAwareSolutions | None]:
        if self._failure is not None:
            raise self._failure
        try:
            message = self._conn.recv()
        except (EOFError, OSError) as exc:
            raise self._ended(type(exc).__name__) from None
        except Exception as exc:  # a damaged message (unpickling): the worker is not trusted
            raise self._ended(f"unreadable answer, {type(exc).__name__}") from None
        if not self._busy or not (isinstance(message, tuple) and len(message) == 3):
            raise self._ended("an answer nobody asked for")
        key, solutions, error = message
        self._busy = False
        if error is not None:
            raise WorkerError("contact_aware_async", str(error)[:200], "the worker failed")
        return key, solutions

    def poll(self) -> ContactAwareSolutions | None:
        """A finished answer, if the worker has one (never waits).

        Raises:
            WorkerError: The worker has ended (its end of the socket closed: also noticed
                while it is idle), or failed on the posture it was given.
        """
        if self._failure is not None:
            raise self._failure
        if self._poller.poll(0):
            return self._receive()[1]
        return None

    @property
    def idle(self) -> bool:
        """Whether the worker waits for a posture (its last answer, if any, collected)."""
        return not self._busy

    def submit(self, key: bytes, q: np.ndarray) -> None:
        """Ask for the rates at configuration ``q`` (nq), continuing the worker's last answer.

        Raises:
            WorkerError: The worker has ended.
        """
        if self._failure is not None:
            raise self._failure
        self._write((key, np.asarray(q)))
        self._busy = True
        self.submitted = key

    def wait(self, timeout: float | None = None) -> ContactAwareSolutions | None:
        """The answer to the request in flight (waits; None after ``timeout`` s)."""
        if self._busy and self._conn.poll(timeout):
            return self._receive()[1]
        return None

    def close(self) -> None:
        """Stop the worker process (idempotent)."""
        self._finalizer()

    @property
    def alive(self) -> bool:
        """Whether the worker process is running."""
        return self._process.poll() is None


if __name__ == "__main__":  # the worker process (started by ContactAwareWorker)
    _serve(Connection(int(sys.argv[1])))
