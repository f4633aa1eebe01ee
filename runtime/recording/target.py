"""Where a recording goes, checked before anything starts (standard library only: the main job checks its
``--record`` path with it before it starts a child).

Invariant: :func:`check_target` either raises :class:`RecordingTargetError` with one line naming the path and the
reason, or the path's folder exists, is writable (a file was created and removed there), the path is no folder,
and the file system has at least :data:`MIN_FREE_BYTES` free.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

__all__ = ["MIN_FREE_BYTES", "RecordingTargetError", "bag_target", "check_target"]

MIN_FREE_BYTES = 16 * 1024 * 1024  # about a minute of the demo mission's recording


class RecordingTargetError(OSError):
    """The recording cannot be written where asked."""


def check_target(path: Path) -> Path:
    """The absolute path of a writable recording file (see the module docstring).

    >>> try:
    ...     check_target(Path("/no/such/run.mcap"))
    ... except RecordingTargetError as ex:
    ...     print(ex)
    cannot record to /no/such/run.mcap: the folder /no/such does not exist
    """
    path = Path(path).expanduser().absolute()
    folder = path.parent
    if path.is_dir():
        raise RecordingTargetError(f"cannot record to {path}: it is a folder")
    if not folder.is_dir():
        raise RecordingTargetError(f"cannot record to {path}: the folder {folder} does not exist")
    try:
        fd, probe = tempfile.mkstemp(prefix=".sam-record-probe-", dir=folder)
        os.close(fd)
        os.unlink(probe)
    except OSError as ex:
        raise RecordingTargetError(f"cannot record to {path}: {folder} is not writable ({ex.strerror})") from None
    if path.exists() and not os.access(path, os.W_OK):
        raise RecordingTargetError(f"cannot record to {path}: the file exists and is not writable")
    try:
        st = os.statvfs(folder)
    except OSError:
        return path
    free = st.f_bavail * st.f_frsize
    if free < MIN_FREE_BYTES:
        raise RecordingTargetError(f"cannot record to {path}: only {free // 1024} KiB free on its file system "
                                   f"(at least {MIN_FREE_BYTES // (1024 * 1024)} MiB needed)")
    return path


def bag_target(folder: Path) -> Path:
    """The MCAP file of a rosbag2 folder to record into (``<folder>/<name>_0.mcap``, rosbag2's naming), the folder
    created; RecordingTargetError as :func:`check_target`, and for a folder that exists and is not empty (rosbag2
    refuses an existing bag folder: a recording never mixes with an older one).

    >>> try:
    ...     bag_target(Path("/no/such/bag"))
    ... except RecordingTargetError as ex:
    ...     print(ex)
    cannot record to /no/such/bag: the folder /no/such does not exist
    """
    folder = Path(folder).expanduser().absolute()
    if not folder.parent.is_dir():
        raise RecordingTargetError(f"cannot record to {folder}: the folder {folder.parent} does not exist")
    if folder.exists() and (not folder.is_dir() or any(folder.iterdir())):
        raise RecordingTargetError(f"cannot record to {folder}: it exists and is not an empty folder (a rosbag2 "
                                   "folder is new)")
    try:
        folder.mkdir(exist_ok=True)
    except OSError as ex:
        raise RecordingTargetError(f"cannot record to {folder}: {ex.strerror}") from None
    return check_target(folder / f"{folder.name}_0.mcap")
