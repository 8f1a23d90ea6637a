"""Robots loaded from files are cached by the bytes they were parsed from."""

from __future__ import annotations

import os
import re

from impact_balance.robot.robot import load_robot


def _urdf_with_mass(text: str, old: str, new: str) -> str:
    assert len(old) == len(new)  # the same size: only the content tells the files apart
    out, n = re.subn(rf'<mass value="{re.escape(old)}"', f'<mass value="{new}"', text, count=1)
    assert n == 1
    return out


def test_a_file_rewritten_with_the_same_size_and_time_is_reloaded(tmp_path):
    """Before, the cache key was (path, mtime, size): a same-size rewrite with its time restored
    gave the old model. Now the key is the digest of the bytes parsed."""
    source = load_robot("g1").urdf_path
    text = source.read_text(encoding="utf-8")
    old = re.search(r'<mass value="([0-9.]+)"', text).group(1)
    new = ("9" if old[0] != "9" else "8") + old[1:]
    urdf = tmp_path / "robot.urdf"
    urdf.write_text(text, encoding="utf-8")
    first = load_robot(None, urdf)
    stat = urdf.stat()
    urdf.write_text(_urdf_with_mass(text, old, new), encoding="utf-8")
    os.utime(urdf, ns=(stat.st_atime_ns, stat.st_mtime_ns))
    second = load_robot(None, urdf)
    delta = float(new) - float(old)
    assert second is not first
    assert abs(_total_mass(second) - _total_mass(first) - delta) < 1e-9
    assert load_robot(None, urdf) is second  # the same bytes: the cached model


def _total_mass(robot) -> float:
    return float(sum(i.mass for i in robot.model.inertias))
