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
``refused_by_board``, ``timeouts``, ``reads``, ``read_failures``. An atomic set (set_parameters_atomically) is all
or nothing: checked whole against the spec first; when a board fails one setting after others were written, those
are written back to what their boards held (``rollbacks``, ``rollback_failures``; the reason names both).

Saving: a value written is lost at the board's next reboot unless the board saves it. Each board with settings gets a
std_srvs/Trigger service ``<device>/store_settings`` (relative: under the bridge's namespace, as the device duties'
``uavcan_restart_node``), which asks the board to save (backends.param_access ``store``) and answers success only on
the board's OK, else the reason (no answer, refused, the link down); counted ``stores``, ``store_failures``. The
services live on a node of their own (``<bridge>_settings``) on the bridge's executor of waiting calls (shared with
the service mappings': backends.spin_thread.WaitingCalls): a store waits up to STORE_TIMEOUT_S for a flash write,
which the bridge's single executor thread must not.

Overrides at start (``--ros-args --params-file F`` or rclpy parameter_overrides naming ``<device>.<setting>``): the
parameter is declared with the override, and after the board's first read of it the override is written to the
board when it differs (logged ``name: board -> override``, counted ``overrides_applied``); one the spec refuses is
not declared (the spec's default is), one the board refuses or does not answer shows the board's value; both are
logged with the reason and counted ``overrides_refused``. Once per start: a board's later reboots are not written
again (what it saved is what it runs with).

The timeout of a read or write is PARAM_TIMEOUT_S: the spec has no per-device or bridge-wide request timeout
(``timeout`` exists only per service mapping and per node-service duty), so none is taken from it.
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

__all__ = ["PARAM_TIMEOUT_S", "STORE_SERVICE", "STORE_TIMEOUT_S", "DeviceParams", "ros_parameter_name"]

PARAM_TIMEOUT_S = 1.0  # a board's answer to one read or write
# A store writes the board's flash: an STM32F4 erases a 128 KiB sector in 1-2 s before it answers, so a store waits
# longer than a read or write (on the store services' own threads: nothing else waits with it).
STORE_TIMEOUT_S = 3.0
STORE_SERVICE = "store_settings"  # <device>/store_settings, relative: under the bridge's namespace


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
    :param access: the protocol's bus access (backends.param_access).
    :param overrides: initial values by ROS name (the bridge's parameter_overrides), before the node's own."""

    def __init__(self, lifetime: Lifetime, ros: Any, devices: Mapping[int, str], params: Sequence[Any],
                 protocol: str, access: ParamAccess, *, timeout: float = PARAM_TIMEOUT_S,
                 overrides: Mapping[str, Any] | None = None) -> None:
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
        self._given = dict(overrides or {})
        self._store_node: Any = None  # the store services' node, on the bridge's executor of waiting calls
        # --params-file / constructor overrides of the boards' settings not yet written: ROS name -> board's form
        self.pending_overrides: dict[str, Stored] = {}

    @property
    def devices(self) -> dict[str, int]:
        """The boards with settings: device name -> node id."""
        return {s.device: s.nid for s in self.settings.values()}

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
        # rclpy's overrides of the node (--params-file, parameter_overrides): rclpy keeps them in this attribute
        # only (node_support reads it the same way)
        overrides = {n: p.value for n, p in (getattr(node, "_parameter_overrides", {}) or {}).items()}
        overrides.update(self._given)
        for name, s in self.settings.items():
            if node.has_parameter(name):  # a managed bridge configured again: its lifecycle node keeps them
                continue
            descriptor = ParameterDescriptor(name=name, description=self._description(s), read_only=False)
            self._ranges(descriptor, s.info)
            value = s.info.default
            if name in overrides:
                value = self._override(name, s, overrides[name])
            self._local.quiet = True
            try:
                # ignore_override: the override was checked above (a bad one would raise out of rclpy here)
                node.declare_parameter(name, value, descriptor, ignore_override=True)
            finally:
                self._local.quiet = False
        self._serve_stores()

    def _override(self, name: str, s: _Setting, value: Any) -> Any:
        """An override of a board's setting: the value to declare (the override, to be written to the board after
        its first read; the spec's default when the spec refuses it: logged and counted, the bridge goes on)."""
        problem = ros_problem(s.info, value)
        stored = to_stored(s.info, value)
        if problem is not None or stored is None:
            self.counts["overrides_refused"] += 1
            log.warning("%s: the override %r is refused by the spec: %s", name, value, problem)
            return s.info.default
        self.pending_overrides[name] = stored
        return float(value) if s.info.type == "real" else value  # (a real given as 3 is declared a double)

    def _serve_stores(self) -> None:
        """A std_srvs/Trigger ``<device>/store_settings`` per board with settings, on a node of its own on the
        executor of waiting calls (a call waits for the board, which the bridge's one executor thread must not)."""
        from rclpy.callback_groups import ReentrantCallbackGroup
        from rclpy.node import Node
        from std_srvs.srv import Trigger

        base = self.ros.name
        # (no parameter services of its own: the settings are the bridge node's parameters, not this node's)
        node = Node(f"{base}_settings", namespace=self.ros.node.get_namespace(), context=self.ros.context,
                    start_parameter_services=False)
        group = ReentrantCallbackGroup()
        for device in self.devices:
            node.create_service(Trigger, f"{device}/{STORE_SERVICE}", self._store_callback(device),
                                callback_group=group)
        self._store_node = node
        self.ros.waiting_calls.add(self.ros.context, node)

    def _store_callback(self, device: str) -> Any:
        def on_call(_request: Any, response: Any) -> Any:
            problem = self.store(device)
            response.success = problem is None
            response.message = problem or f"{device} stored its settings"
            return response

        return on_call

    def _close(self) -> None:
        node, self._store_node = self._store_node, None
        if node is not None:
            self.ros.waiting_calls.remove(node)
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
        and confirmed; the first failure ends the set with its reason.

        rclpy calls it once per parameter for set_parameters and once with all of them for
        set_parameters_atomically. For the atomic set, all or nothing: every value is checked against the spec
        before any is written, and when a board fails one after others were written, those are written back to
        the values their boards held (counted ``rollbacks``; a rollback that fails is named in the reason)."""
        from rcl_interfaces.msg import SetParametersResult

        ours = [p for p in parameters if p.name in self.settings]
        if not ours or getattr(self._local, "quiet", False):
            return SetParametersResult(successful=True)
        for parameter in ours:
            refusal = self._spec_refusal(self.settings[parameter.name], parameter.value)
            if refusal is not None:
                self.counts["sets"] += 1
                return SetParametersResult(successful=False, reason=f"{parameter.name}: {refusal}")
        written: list[tuple[str, Any]] = []  # (name, what its board held before)
        for parameter in ours:
            before = self.board_values.get(parameter.name)
            problem = self._set_one(parameter.name, parameter.value)
            if problem is not None:
                return SetParametersResult(successful=False,
                                           reason=f"{parameter.name}: {problem}{self._roll_back(written)}")
            written.append((parameter.name, before))
        return SetParametersResult(successful=True)

    def _roll_back(self, written: list[tuple[str, Any]]) -> str:
        """The settings of a failed atomic set that were written, written back (last first): what to add to its
        reason."""
        if not written:
            return ""
        back, failed = [], []
        for name, before in reversed(written):
            s = self.settings[name]
            if before is None:
                failed.append(f"{name} (its earlier value was never read)")
                continue
            self.counts["rollbacks"] += 1
            answer, problem = self._write(s, before)
            if problem is None and answer is not None:
                self.board_values[name] = answer
                if _same(s.info.type, answer, before):
                    back.append(name)
                    continue
                problem = f"it keeps {from_stored(s.info, answer)!r}"
                # rclpy keeps the parameter's old value for a failed set: show the board's once the set is over
                if self._loop is not None and not self._loop.is_closed():
                    self._loop.call_soon_threadsafe(self._show, name, from_stored(s.info, answer))
            self.counts["rollback_failures"] += 1
            failed.append(f"{name} ({problem})")
        text = f"; written back: {', '.join(back)}" if back else ""
        return text + (f"; NOT written back: {', '.join(failed)}" if failed else "")

    def _spec_refusal(self, s: _Setting, value: Any) -> str | None:
        """Why the spec refuses ``value`` for ``s`` (counted ``refused_by_spec``), or None."""
        problem = ros_problem(s.info, value)
        if problem is None:
            return None
        self.counts["refused_by_spec"] += 1
        return f"refused by the spec: {problem}"

    def _set_one(self, name: str, value: Any) -> str | None:
        s = self.settings[name]
        self.counts["sets"] += 1
        refusal = self._spec_refusal(s, value)
        if refusal is not None:
            return refusal
        stored = to_stored(s.info, value)
        assert stored is not None
        answer, problem = self._write(s, stored)
        if problem is not None:
            return problem
        self.board_values[name] = answer
        if not _same(s.info.type, answer, stored):
            self.counts["refused_by_board"] += 1
            return f"refused by {s.device} (node {s.nid}): it keeps {from_stored(s.info, answer)!r}"
        self.pending_overrides.pop(name, None)  # a value set since the start is newer than the start's override
        return None

    def _write(self, s: _Setting, stored: Any) -> tuple[Any, str | None]:
        """Write ``stored`` to the board of ``s`` on the loop and wait for its answer (from the executor thread):
        (the value the board answered with, None) or (None, why there is none; counted)."""
        loop = self._loop
        if loop is None or loop.is_closed() or self.lifetime.closed:
            return None, "the bridge is not running"
        future = asyncio.run_coroutine_threadsafe(self.access(s.nid, s.bus_name, s.info.type, stored,
                                                              self.timeout), loop)
        try:
            return future.result(self.timeout + 2.0), None  # the access's own timeout ends it; this guards the loop
        except ParamIOError as ex:
            self.counts["timeouts" if "did not answer" in str(ex) else "failures"] += 1
            return None, f"{s.device}: {ex}"
        except TimeoutError:
            future.cancel()
            self.counts["timeouts"] += 1
            return None, f"the bridge's loop did not answer within {self.timeout + 2.0:g} s"
        except Exception as ex:
            self.counts["failures"] += 1
            return None, f"{s.device}: {type(ex).__name__}: {ex}"

    def store(self, device: str) -> str | None:
        """Ask board `device` to save its current values (the store service's thread; waits for its answer): None
        on its OK, else the reason (no answer, refused, the link down). Counted: ``stores``, ``store_failures``."""
        self.counts["stores"] += 1
        nid = self.devices.get(device)
        loop = self._loop
        problem: str | None = None
        if nid is None:
            problem = f"{device} is no board with settings of this bridge"
        elif loop is None or loop.is_closed() or self.lifetime.closed:
            problem = "the bridge is not running"
        else:
            future = asyncio.run_coroutine_threadsafe(self.access.store(nid, STORE_TIMEOUT_S), loop)
            try:
                future.result(STORE_TIMEOUT_S + 2.0)  # the access's own timeout ends it; this guards the loop
            except ParamIOError as ex:
                problem = f"{device}: {ex}"
            except TimeoutError:
                future.cancel()
                problem = f"the bridge's loop did not answer within {STORE_TIMEOUT_S + 2.0:g} s"
            except Exception as ex:  # a bug: the caller gets it as the reason, never a traceback
                problem = f"{device}: {type(ex).__name__}: {ex}"
        if problem is not None:
            self.counts["store_failures"] += 1
            log.warning("storing the settings of %s: %s", device, problem)
        else:
            log.info("%s (node %s) stored its settings", device, nid)
        return problem

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
                if name in self.pending_overrides:
                    answer = await self._write_override(name, s, answer)
                self._show(name, from_stored(s.info, answer))
        finally:
            self._reading.discard(nid)

    async def _write_override(self, name: str, s: _Setting, board: Stored) -> Stored:
        """The override of setting `name` written to its board after the board's first read, when it differs from
        the board's value (the loop's thread): logged ``name: board -> override`` and counted
        (``overrides_applied``; ``overrides_refused`` with the reason). Once per bridge start: an override the
        board refused is not tried again. Returns the board's value after it."""
        wanted = self.pending_overrides.pop(name, None)  # (None: a ROS set since took its place, another thread)
        if wanted is None or _same(s.info.type, board, wanted):
            return board
        change = f"{name}: {from_stored(s.info, board)!r} -> {from_stored(s.info, wanted)!r}"
        try:
            answer = await self.access(s.nid, s.bus_name, s.info.type, wanted, self.timeout)
        except Exception as ex:  # ParamIOError; anything else is a bug, counted and logged, never raised
            self.counts["overrides_refused"] += 1
            log.warning("%s REFUSED: %s", change, ex if isinstance(ex, ParamIOError) else f"{type(ex).__name__}: {ex}")
            return board
        self.board_values[name] = answer
        if not _same(s.info.type, answer, wanted):
            self.counts["overrides_refused"] += 1
            log.warning("%s REFUSED: %s (node %s) keeps %r", change, s.device, s.nid, from_stored(s.info, answer))
            return answer
        self.counts["overrides_applied"] += 1
        log.info("%s (the override written to the board)", change)
        return answer

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
