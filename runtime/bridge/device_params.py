"""The boards' settings as ROS 2 parameters of the bridge's node (issue 28): ``<device>.<setting>``, e.g.
``thruster_1.motor.pole_count``.

Why on the bridge's node: a ROS driver exposes its hardware's settings as its own parameters (one node per driver,
dotted names per sub-device: the camera and lidar drivers do so), so ``ros2 param list /uavcan_ros_bridge`` shows
every board, one params file saves and restores them all, and no node appears per board. Each is declared with a
ParameterDescriptor from the spec: its description (with the unit, and "restart" when a change needs one), an
integer_range / floating_point_range from its range, and additional_constraints naming an enum's values or a
string's longest length; an enum is a string parameter holding the value's name.

A set (the standard rcl parameter services; the on-set callback runs on the bridge's rclpy executor thread):
checked against the spec first (type, range, enum name: SetParametersResult successful=false with the reason, no
bus traffic), then handed to the asyncio loop (which owns the protocol's node: the bus I/O runs there, awaited, so
the loop goes on with everything else), written to the board (register.Access / param.GetSet) and confirmed by the
value the board answers with: a board that keeps another value (it refused the write) or does not answer within
the timeout fails the set with the reason, never a silent success. The executor thread waits for that answer (at
most the timeout): a set holds up the bridge's other ROS callbacks that long, which is why the timeout is short.

On first contact (the device's first heartbeat), when it is back and after a restart, the loop reads each
setting of the board (one request at a time, no timer of its own) and shows the board's value as the parameter's
(an update the on-set callback lets through without writing it back). Counted: ``sets``, ``refused_by_spec``,
``refused_by_board``, ``timeouts``, ``reads``, ``read_failures``.
"""

from __future__ import annotations

import asyncio
import collections
import math
import struct
import threading
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from sam_runtime.bridge.backends.param_access import ParamAccess, ParamIOError
from sam_runtime.bridge.counters import log
from sam_runtime.bridge.lifetime import Lifetime
from sam_runtime.common.board_settings import Stored, default_stored, from_stored, ros_problem, to_stored

__all__ = ["PARAM_TIMEOUT_S", "DeviceParams", "ros_parameter_name"]

PARAM_TIMEOUT_S = 1.0  # a board's answer to one read or write


def ros_parameter_name(device: str, setting: str) -> str:
    return f"{device}.{setting}"


@dataclass(frozen=True)
class _Setting:
    device: str
    nid: int
    info: Any  # the tables' DeviceParameterInfo
    bus_name: str  # its name on the bridge's protocol


def _same(kind: str, a: Stored, b: Stored) -> bool:
    """Whether the board's answer confirms a write (a real travels as float32 both ways)."""
    if kind == "real" and isinstance(a, int | float) and isinstance(b, int | float):
        f32 = struct.Struct("<f")
        return math.isclose(f32.unpack(f32.pack(float(a)))[0], f32.unpack(f32.pack(float(b)))[0])
    return a == b


class DeviceParams:
    """:param devices: node id -> device name of this bridge's devices (its layout's protocol).
    :param params: the tables' DEVICE_PARAMETERS; those of other devices are left out.
    :param access: the protocol's bus access (backends.param_access)."""

    def __init__(self, lifetime: Lifetime, ros: Any, devices: Mapping[int, str], params: Sequence[Any],
                 protocol: str, access: ParamAccess, *, timeout: float = PARAM_TIMEOUT_S) -> None:
        self.lifetime, self.ros, self.access, self.timeout = lifetime, ros, access, float(timeout)
        nids = {name: nid for nid, name in devices.items()}
        self.settings = {ros_parameter_name(p.device, p.name): _Setting(p.device, nids[p.device], p,
                                                                          p.name_on(protocol))
                         for p in params if p.device in nids}
        self.counts: collections.Counter[str] = collections.Counter()
        self.board_values: dict[str, Stored] = {}  # the last value each board answered with, by ROS name
        self._local = threading.local()  # .quiet: the loop's own update of a parameter (no write back)
        self._loop: asyncio.AbstractEventLoop | None = None
        self._reading: set[int] = set()
        self._node: Any = None  # the ROS node the parameters are declared on
        self._tasks: set[asyncio.Task[None]] = set()

    def attach(self) -> None:
        """After the ROS side's attach (its node exists at start)."""
        if self.settings:
            self.lifetime.add_hooks("device parameters", start=self._start, close=self._close)

    # ------------------------------------------------------------------------------------------------ ROS side
    def _start(self) -> None:
        from rcl_interfaces.msg import ParameterDescriptor

        self._loop = asyncio.get_running_loop()
        node = self._node = self.ros.node
        node.add_on_set_parameters_callback(self._on_set)
        for name, s in self.settings.items():
            if node.has_parameter(name):  # a managed bridge configured again: its lifecycle node keeps them
                continue
            descriptor = ParameterDescriptor(name=name, description=self._description(s), read_only=False)
            self._ranges(descriptor, s.info)
            self._local.quiet = True
            try:
                node.declare_parameter(name, s.info.default, descriptor)
            finally:
                self._local.quiet = False

    def _close(self) -> None:
        for task in list(self._tasks):  # reads in flight: their node is closing
            task.cancel()
        if self._node is not None:  # a managed bridge's node outlives this bridge (cleanup, configure again)
            try:
                self._node.remove_on_set_parameters_callback(self._on_set)
            except Exception:  # the node is already destroyed (a plain bridge closes it after this)
                pass
            self._node = None

    @staticmethod
    def _description(s: _Setting) -> str:
        p = s.info
        extra = [f"unit {p.unit}"] if p.unit else []
        extra += ["takes effect after a restart"] if p.restart else []
        extra += [f"{s.bus_name!r} on node {s.nid}"]
        return (p.description + " " if p.description else "") + f"({', '.join(extra)})"

    @staticmethod
    def _ranges(descriptor: Any, p: Any) -> None:
        from rcl_interfaces.msg import FloatingPointRange, IntegerRange

        if p.type == "integer" and p.minimum is not None and p.maximum is not None:
            descriptor.integer_range = [IntegerRange(from_value=int(p.minimum), to_value=int(p.maximum), step=0)]
        elif p.type == "real" and p.minimum is not None and p.maximum is not None:
            descriptor.floating_point_range = [FloatingPointRange(from_value=float(p.minimum),
                                                                  to_value=float(p.maximum), step=0.0)]
        elif p.type == "enum":
            descriptor.additional_constraints = "one of: " + ", ".join(n for n, _ in p.values)
        elif p.type == "string" and p.max_length is not None:
            descriptor.additional_constraints = f"at most {p.max_length} bytes (UTF-8)"

    def _on_set(self, parameters: list[Any]) -> Any:
        """The on-set callback (the executor thread): every board setting among ``parameters`` checked, written
        and confirmed; the first failure ends the set with its reason."""
        from rcl_interfaces.msg import SetParametersResult

        ours = [p for p in parameters if p.name in self.settings]
        if not ours or getattr(self._local, "quiet", False):
            return SetParametersResult(successful=True)
        for parameter in ours:
            problem = self._set_one(parameter.name, parameter.value)
            if problem is not None:
                return SetParametersResult(successful=False, reason=f"{parameter.name}: {problem}")
        return SetParametersResult(successful=True)

    def _set_one(self, name: str, value: Any) -> str | None:
        s = self.settings[name]
        self.counts["sets"] += 1
        problem = ros_problem(s.info, value)
        if problem is not None:
            self.counts["refused_by_spec"] += 1
            return f"refused by the spec: {problem}"
        stored = to_stored(s.info, value)
        assert stored is not None
        loop = self._loop
        if loop is None or loop.is_closed() or self.lifetime.closed:
            return "the bridge is not running"
        future = asyncio.run_coroutine_threadsafe(self.access(s.nid, s.bus_name, s.info.type, stored,
                                                              self.timeout), loop)
        try:
            answer = future.result(self.timeout + 2.0)  # the access's own timeout ends it; this guards the loop
        except ParamIOError as ex:
            self.counts["timeouts" if "did not answer" in str(ex) else "failures"] += 1
            return f"{s.device}: {ex}"
        except TimeoutError:
            future.cancel()
            self.counts["timeouts"] += 1
            return f"the bridge's loop did not answer within {self.timeout + 2.0:g} s"
        except Exception as ex:
            self.counts["failures"] += 1
            return f"{s.device}: {type(ex).__name__}: {ex}"
        self.board_values[name] = answer
        if not _same(s.info.type, answer, stored):
            self.counts["refused_by_board"] += 1
            return f"refused by {s.device} (node {s.nid}): it keeps {from_stored(s.info, answer)!r}"
        return None

    # ------------------------------------------------------------------------------------------------ reads
    def on_health(self, nid: int, event: str, device: bool) -> None:
        """The device-health handler (the loop's thread): read a board's settings when it appears, comes back or
        restarted."""
        if not device or event not in ("first", "back", "restarted") or nid in self._reading:
            return
        if self._loop is None or not any(s.nid == nid for s in self.settings.values()):
            return
        self._reading.add(nid)
        task = self._loop.create_task(self._read_board(nid), name=f"read-settings-{nid}")
        self._tasks.add(task)
        task.add_done_callback(self._tasks.discard)

    async def _read_board(self, nid: int) -> None:
        try:
            for name, s in self.settings.items():
                if s.nid != nid or self.lifetime.closed:
                    continue
                try:
                    answer = await self.access(nid, s.bus_name, s.info.type, None, self.timeout)
                except Exception as ex:  # ParamIOError; anything else is a bug, counted and logged, never raised
                    self.counts["read_failures"] += 1
                    log.warning("%s: reading %s: %s", s.device, s.bus_name,
                                ex if isinstance(ex, ParamIOError) else f"{type(ex).__name__}: {ex}")
                    continue
                self.counts["reads"] += 1
                self.board_values[name] = answer
                self._show(name, from_stored(s.info, answer))
        finally:
            self._reading.discard(nid)

    def _show(self, name: str, value: Stored) -> None:
        from rclpy.parameter import Parameter

        node = self.ros.node
        if node is None or node.get_parameter(name).value == value:
            return
        self._local.quiet = True
        try:
            node.set_parameters([Parameter(name, value=value)])
        except Exception as ex:  # a value of another type than the declared one (a board off the spec)
            self.counts["read_failures"] += 1
            log.warning("%s: the board's value %r cannot be shown: %s", name, value, ex)
        finally:
            self._local.quiet = False

    def differing(self) -> dict[str, tuple[Stored, Stored]]:
        """The settings whose board value differs from the spec's default: name -> (board value, default)."""
        out = {}
        for name, answer in self.board_values.items():
            s = self.settings[name]
            shown = from_stored(s.info, answer)
            if not _same(s.info.type, answer, default_stored(s.info)):
                out[name] = (shown, s.info.default)
        return out

    def differing_by_device(self) -> dict[str, str]:
        """device -> "setting value (spec default), ..." for the boards whose values differ from the spec's."""
        out: dict[str, list[str]] = {}
        for name, (value, default) in self.differing().items():
            s = self.settings[name]
            out.setdefault(s.device, []).append(f"{s.info.name} {value} (spec {default})")
        return {device: ", ".join(items) for device, items in out.items()}

    def snapshot(self) -> dict[str, Any]:
        return {"count": len(self.settings), **dict(self.counts),
                "differing": {k: list(v) for k, v in self.differing().items()}}
