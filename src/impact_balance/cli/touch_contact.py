"""``--touch-contact``: the ``id`` controller's touching point as a contact of its QP.

The option of the impact trial commands (``validate``, ``approach``): the trials' controller
adds the impacting point to its QP's contacts from its first touch until its withdrawal
(:attr:`impact_balance.sim.control.gains.InverseDynamicsGains.touch_contact`). The criterion and
the predictions do not change.
"""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from impact_balance.sim.trials.setup import BalanceTrialOptions

__all__ = ["TOUCH_CONTACT_OPTION", "add_touch_contact_option", "impact_trial_options"]

#: The option's name.
TOUCH_CONTACT_OPTION = "--touch-contact"


def add_touch_contact_option(parser: argparse.ArgumentParser) -> None:
    """Add ``--touch-contact`` (a flag, off by default).

    Args:
        parser: The command's parser.
    """
    parser.add_argument(
        TOUCH_CONTACT_OPTION,
        action="store_true",
        help="id controller: from the impact point's first touch until its withdrawal starts, "
        "the point is a contact of the controller's QP (it stays; its force in the impact's "
        "friction cone times the controller's friction scale, pressing with at least the "
        "withdrawal's force threshold, 15 N); default: the impact is no contact of the QP",
    )


def impact_trial_options(
    controller: str, rigid_impact: bool, touch_contact: bool
) -> BalanceTrialOptions:
    """The trials' options of an impact command.

    Args:
        controller: ``--controller`` (``ik`` or ``id``).
        rigid_impact: ``--rigid-impact``.
        touch_contact: ``--touch-contact``.

    Returns:
        The options, with the ``id`` gains' ``touch_contact`` set.

    Raises:
        SimulationError: ``--touch-contact`` with a controller other than ``id``.
    """
    from impact_balance.exceptions import SimulationError
    from impact_balance.sim.control.gains import InverseDynamicsGains
    from impact_balance.sim.trials.setup import BalanceTrialOptions

    if touch_contact and controller != "id":
        raise SimulationError(
            TOUCH_CONTACT_OPTION,
            True,
            f"only the id controller has a touch contact, not {controller!r} (--controller id)",
        )
    return BalanceTrialOptions(
        controller=controller,  # type: ignore[arg-type]
        rigid_impact=rigid_impact,
        id_gains=InverseDynamicsGains(touch_contact=touch_contact),
    )
