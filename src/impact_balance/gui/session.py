"""One GUI session: the current state, its analysis, and all-or-nothing edits.

Every edit (a field, a load, a gizmo drag) builds a new :class:`~.state.GuiState`, analyses
it with :func:`impact_balance.analyze` and only then replaces the current one. A refused edit
(a bad value, an unknown frame, an IK failure...) leaves the session as it was and sets
:attr:`Session.message`; nothing raises. An infeasible stance is not refused: it is an answer
("cannot balance"), shown as such.
"""

from __future__ import annotations

import logging
import math
import threading
import time
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import pinocchio as pin

from impact_balance.analysis.analyze import Analysis, analyze
from impact_balance.exceptions import ImpactBalanceError
from impact_balance.gui.drag import DragTarget, drag_changes
from impact_balance.gui.files import GuiFiles, describe
from impact_balance.gui.state import DEFAULT_SCENARIO, FieldPath, GuiState
from impact_balance.gui.workspace import Workspace

if TYPE_CHECKING:
    from impact_balance.analysis.held_stance import HeldStanceLimit
    from impact_balance.analysis.reach import ReachAnswer
    from impact_balance.balance.reach import ComReach, ReachOptions
    from impact_balance.governor import Governor

__all__ = ["Governed", "Session", "Summary", "format_speed"]

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class Governed:
    """What the governor (:mod:`impact_balance.governor`) allows from the stance being edited.

    Attributes:
        ceiling: The largest approach speed it lets through, m/s (inf: no speed is unsafe).
        status: The criterion's status ("ok", "unbounded", "already_falling"...).
        tick_us: The governor's time for this tick, microseconds.
        reference: The reference velocity's approach speed, m/s (None without one).
        capped: The capped reference's approach speed, m/s (None without one).
    """

    ceiling: float
    status: str
    tick_us: float
    reference: float | None
    capped: float | None


def format_speed(value: float | None) -> str:
    """An approach speed for display: ``0.481 m/s``, ``unbounded`` or ``-`` (no impact)."""
    if value is None:
        return "-"
    return f"{value:.3f} m/s" if math.isfinite(value) else "unbounded"


@dataclass(frozen=True)
class Summary:
    """The numbers the GUI shows for an analysis.

    Attributes:
        verdict: "balanced", "falling: ..." or "cannot balance: ..." (see
            :attr:`Analysis.verdict`).
        can_balance: Whether the contacts can hold the robot at rest.
        max_contact_velocity: Maximum approach speed by the CoM velocity criterion (with the
            scenario's angular momentum term when set: ``ImpactAnswer.default``), m/s (``inf``
            unbounded, None without an impact).
        zmp_max_contact_velocity: The same by the ZMP criterion, m/s.
        reference_speed: Approach speed of the reference velocity, m/s (None without one).
        falls_at_reference: Whether the reference approach speed exceeds the maximum.
        warnings: The analysis' warnings, one line each (see
            :mod:`impact_balance.analysis.diagnostics`).
    """

    verdict: str
    can_balance: bool
    max_contact_velocity: float | None
    zmp_max_contact_velocity: float | None
    reference_speed: float | None
    falls_at_reference: bool
    warnings: tuple[str, ...] = ()

    @classmethod
    def of(cls, analysis: Analysis) -> Summary:
        """The summary of ``analysis``.

        The reference falls when its approach speed exceeds the maximum by more than 1e-12 m/s.
        """
        im = analysis.impact
        vmax = zmp = ref = None
        falls = False
        if im is not None:
            vmax, zmp = im.default.max_contact_velocity, im.zmp_max_contact_velocity
            v_ref = im.model.spec.reference_velocity
            if v_ref is not None:
                ref = max(0.0, im.model.approach_speed(v_ref))
                falls = ref > vmax + 1e-12
        warnings = tuple(str(w) for w in analysis.warnings)
        return cls(analysis.verdict, analysis.areas.can_balance, vmax, zmp, ref, falls, warnings)

    @property
    def headline(self) -> str:
        """The verdict in a few words: "balanced", "falling" or "cannot balance"."""
        return self.verdict.split(":")[0]


class Session:
    """The GUI's model: state, analysis, last message. Thread-safe (one edit at a time).

    Args:
        state: The first state: a :class:`GuiState`, or a scenario file or bundled name given
            on the command line (read as is; later loads go through the workspace).
        workspace: The folder every load and save from the GUI is confined to.

    Attributes:
        state: The current (valid) state.
        files: Loads, uploads and saves, confined to the workspace.
        analysis: Its analysis.
        message: Why the last edit was refused, or a note about it (None when all went well).
        refused: Whether the last edit was refused.
        analysis_ms: Wall time of the last successful validation + analysis, ms.
        lock: Re-entrant lock held during every edit (the app holds it while redrawing).
        reach: The CoM's reach of the current stance and what it limits (:meth:`compute_reach`;
            None until asked, and again after an edit that changes the stance).
        held_stance: The held-stance maximum contact velocity of the current analysis
            (:meth:`compute_held_stance`; None until asked, and again after any accepted edit).
    """

    def __init__(
        self,
        state: GuiState | str | Path = DEFAULT_SCENARIO,
        workspace: Workspace | str | Path = ".",
    ):
        self.files = GuiFiles(workspace)
        if not isinstance(state, GuiState):
            state = GuiState.from_file(state)
        self.lock = threading.RLock()
        self.state = state
        self.analysis: Analysis = analyze(state.scenario)
        self.message: str | None = None
        self.refused = False
        self.analysis_ms = 1e3 * self.analysis.timings.get("total", 0.0)
        #: Incremented on every accepted change (the app redraws when it moves).
        self.revision = 0
        self._governor: Governor | None = None
        self._governor_key: str | None = None
        #: The governor's answer for the stance being edited (None without an impact): see
        #: :meth:`_govern`.
        self.governed: Governed | None = None
        self._govern()
        self.reach: ReachAnswer | None = None
        self._reach_of: tuple[str, bytes, str] | None = None  # the stance of ``reach``
        self.held_stance: HeldStanceLimit | None = None

    # -- edits ----------------------------------------------------------------------------
    def _commit(self, build: Callable[[], GuiState], note: str | None = None) -> bool:
        """Build a state, analyse it, and make it current; False (and a message) if refused."""
        with self.lock:
            t0 = time.perf_counter()
            try:
                state = build()
                analysis = analyze(state.scenario)
            except Exception as exc:
                return self._refuse(exc, "applying an edit")
            self.state, self.analysis = state, analysis
            self.analysis_ms = 1e3 * (time.perf_counter() - t0)
            self.message, self.refused = note, False
            self.revision += 1
            self._govern()
            self._follow_reach()
            self.held_stance = None  # the analysis changed: asked again on demand
            return True

    def _govern(self) -> None:
        """Ask the scenario's governor for the speed allowed from this posture and CoM velocity.

        The governor is rebuilt when anything but the posture and the CoM velocity changed; the
        reference velocity is capped by its answer. A governor failure is only logged (the
        analysis went through): :attr:`governed` is then None.
        """
        scenario = self.state.scenario
        if scenario.impact is None or not self.analysis.areas.can_balance:
            self.governed = None
            return
        from impact_balance.governor import Governor

        key = scenario.model_dump_json(
            exclude={"configuration", "joints", "base", "com_velocity", "name", "description"}
        )
        try:
            governor = self._governor
            if governor is None or key != self._governor_key:
                governor = Governor(scenario)
                self._governor, self._governor_key = governor, key
            t0 = time.perf_counter()
            limit = governor.limit_com(self.analysis.stance.q, scenario.com_velocity)
            tick_us = 1e6 * (time.perf_counter() - t0)
            reference = scenario.impact.reference_velocity
            capped = None if reference is None else limit.cap(reference)
        except ImpactBalanceError as exc:  # the analysis went through: only a note
            self.governed = None
            log.info("governor: %s", exc)
            return
        self.governed = Governed(
            limit.ceiling,
            limit.status,
            tick_us,
            None if reference is None else float(-np.dot(reference, limit.normal)),
            None if capped is None else float(-np.dot(capped, limit.normal)),
        )

    def compute_reach(self, options: ReachOptions | None = None) -> bool:
        """The CoM's reach of the current stance into :attr:`reach` (whole-body IK: seconds).

        :func:`~impact_balance.analysis.reach.reach_answer` of the current analysis, with the
        search ``options`` (None: the default search). An edit that keeps the stance (robot,
        configuration, contact frames) keeps the reach and answers again with it; one that
        changes the stance clears it. Returns False (and :attr:`message`) when the search
        fails.
        """
        from impact_balance.analysis.reach import reach_answer

        with self.lock:
            try:
                answer = reach_answer(self.analysis, options)
            except Exception as exc:
                return self._refuse(exc, "computing the CoM's reach")
            self.reach, self._reach_of = answer, _stance_key(self.analysis)
            radii = answer.reach.radii
            self.message = (
                f"CoM reach at constant height: {1000 * radii.min():.0f} to "
                f"{1000 * radii.max():.0f} mm"
            )
            return True

    def compute_held_stance(self) -> bool:
        """The held-stance maximum contact velocity of the analysis into :attr:`held_stance`.

        :func:`~impact_balance.analysis.held_stance.held_stance_max_contact_velocity` (the paper's
        answer where its fixed point is not reached, ``fell_back``). Any accepted edit clears
        it. Returns False (and :attr:`message`) when it cannot be computed (no impact).
        """
        from impact_balance.analysis.held_stance import held_stance_max_contact_velocity

        with self.lock:
            try:
                answer = held_stance_max_contact_velocity(self.analysis)
            except Exception as exc:
                return self._refuse(exc, "computing the held-stance model")
            self.held_stance = answer
            if answer.fell_back:
                how = "the fixed point was not reached: the paper's answer"
            elif answer.binding_restitution is None:
                how = "no approach speed leaves the area"
            else:
                how = f"binding restitution {answer.binding_restitution:g}"
            self.message = (
                f"held-stance max contact velocity {format_speed(answer.max_contact_velocity)} "
                f"({how})"
            )
            return True

    def _follow_reach(self) -> None:
        """After an edit: keep the reach for the same stance (answered again), else clear it."""
        if self.reach is None:
            return
        if _stance_key(self.analysis) != self._reach_of:
            self.reach = self._reach_of = None
            return
        from impact_balance.analysis.reach import reach_answer

        kept: ComReach = self.reach.reach
        self.reach = reach_answer(self.analysis, reach=kept)

    def refuse(self, message: str) -> None:
        """Show ``message`` as a refusal (an upload cut while it arrived); the state is kept."""
        with self.lock:
            self.message, self.refused = " ".join(str(message).split())[:300], True

    def apply(self, changes: Mapping[FieldPath, Any] | Iterable[tuple[FieldPath, Any]]) -> bool:
        """Apply scenario changes; False (and :attr:`message`) when refused."""
        changes = dict(changes.items() if isinstance(changes, Mapping) else changes)
        return self._commit(lambda: self.state.with_changes(changes))

    def set(self, path: FieldPath, value: Any) -> bool:
        """Set one field; False (and :attr:`message`) when refused."""
        return self.apply({tuple(path): value})

    def replace(self, state: GuiState) -> bool:
        """Switch to another (already parsed) state."""
        return self._commit(lambda: state)

    def _refuse(self, exc: Exception, doing: str) -> bool:
        """Refuse what raised ``exc`` while ``doing``: its message shown, the session unchanged.

        An :class:`~impact_balance.exceptions.ImpactBalanceError` is bad input (its message names
        the field); anything else is logged with its traceback. Returns False (refused).
        """
        if isinstance(exc, ImpactBalanceError):
            self.message = describe(exc, self.files.workspace)
        else:
            log.exception("unexpected error while %s", doing)
            self.message = describe(exc)
        self.refused = True
        return False

    @staticmethod
    def _read(read: Callable[[], GuiState]) -> GuiState | BaseException:
        """A state read and parsed by ``read``, or what it raised (kept for :meth:`commit`)."""
        try:
            return read()
        except ImpactBalanceError as exc:
            return exc
        except Exception as exc:
            log.exception("unexpected error while reading a scenario")
            return exc

    def read_file(self, name: str) -> GuiState | BaseException:
        """Read and parse a load (see :meth:`load`) *without* the session lock.

        Returns the state, or the error to show; :meth:`commit` makes it current. The GUI
        calls this before taking the lock, so a slow or hostile file never stops other pages.
        """
        return self._read(lambda: self.files.load(name))

    def read_upload(self, filename: str, content: bytes) -> GuiState | BaseException:
        """Parse an upload (see :meth:`upload`) without the session lock, as :meth:`read_file`."""
        return self._read(lambda: self.files.upload(filename, content))

    def commit(self, read: GuiState | BaseException) -> bool:
        """Make a state read by :meth:`read_file` or :meth:`read_upload` current, or show its error.

        The state is analysed under the lock. Returns False (and :attr:`message`) when refused.
        """
        if isinstance(read, BaseException):
            with self.lock:
                self.message, self.refused = describe(read, self.files.workspace), True
            return False
        return self._commit(lambda: read)

    def load(self, name: str) -> bool:
        """Load a bundled scenario by name, or a workspace ``.yaml`` file by its relative name.

        The file is read and parsed outside the session lock; only the analysis holds it.
        """
        return self.commit(self.read_file(name))

    def upload(self, filename: str, content: bytes) -> bool:
        """Load an uploaded scenario file (its bytes; size-limited, parsed like a file).

        The YAML is parsed outside the session lock; only the analysis holds it.
        """
        return self.commit(self.read_upload(filename, content))

    def load_yaml(self, text: str, source: str | None = None) -> bool:
        """Load scenario YAML text, as an upload named ``source``."""
        return self.upload(source or "uploaded.yaml", text.encode("utf-8"))

    def save(self, name: str, overwrite: bool = False) -> Path | None:
        """Save the current state to a workspace file; None (and :attr:`message`) if refused.

        An existing file is replaced only with ``overwrite`` (the GUI's confirmation box). The
        file's ``name`` is its stem (``ramp.yaml`` is named ``ramp``); when that changes the
        name, the ``description`` says which scenario it was edited from. The session then
        holds what was written (its name, its file).
        """
        with self.lock:
            try:
                state = self.state.saved_as(name)
                out = self.files.save(state, name, overwrite=overwrite)
            except ImpactBalanceError as exc:
                self.message, self.refused = describe(exc, self.files.workspace), True
                return None
            saved = GuiState(state.raw, str(out), state.robot_reader)
            self._commit(lambda: saved, note=f"saved {self.files.workspace.relative(out)}")
            return out

    def drag(self, target: DragTarget, pose: pin.SE3) -> bool:
        """Move a contact or the impact point to a world pose by IK, other contacts fixed."""
        with self.lock:
            note: list[str] = []

            def build() -> GuiState:
                result = drag_changes(self.state, self.analysis.stance, target, pose)
                if not result.reached:
                    away = f"{1e3 * result.residual:.0f} mm away"
                    note.append(f"out of reach: moved as close as possible ({away})")
                return self.state.with_changes(result.changes)

            ok = self._commit(build)
            if ok and note:
                self.message = note[0]
            return ok

    # -- reading --------------------------------------------------------------------------
    @property
    def summary(self) -> Summary:
        """The numbers shown for the current analysis."""
        return Summary.of(self.analysis)


def _stance_key(analysis: Analysis) -> tuple[str, bytes, str]:
    """What the CoM's reach depends on: the robot, the configuration, the contact frames."""
    stance = analysis.stance
    contacts = repr([(c.spec.frame, c.spec.offset.homogeneous.tobytes()) for c in stance.contacts])
    return stance.robot.name, np.asarray(stance.q, dtype=float).tobytes(), contacts
