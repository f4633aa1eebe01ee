"""Cyphal transports and pycyphal.application nodes for the SAM runtime.

- :func:`make_transport` builds a transport from explicit arguments (no DSDL needed).
- :func:`transport_from_env` builds one from the standard register environment variables
  (``UAVCAN__NODE__ID``, ``UAVCAN__UDP__IFACE``, ``UAVCAN__CAN__IFACE``, ``UAVCAN__CAN__MTU``, ...)
  through pycyphal.application's own register-based factory.
- :func:`make_node` / :func:`make_node_from_env` build a started-or-not pycyphal.application node
  (heartbeat, GetInfo, uavcan.register.Access/List) with an in-memory registry: no register file is ever
  written.

Construct transports and nodes from inside a running asyncio event loop (``async def``): pycyphal's media
bind to the current loop when they are created. Close nodes with ``node.close()`` (closes the transport too)
and transports with ``transport.close()``, also from inside the loop, before the loop ends.
"""

from __future__ import annotations

import asyncio
import functools
import logging
import os
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from sam_runtime.cyphal_io.dsdl_cache import ensure_compiled, find_compiled
from sam_runtime.cyphal_io.udp_sessions import loop_sessions_udp_transport

if TYPE_CHECKING:  # pragma: no cover
    import pycyphal.application
    import pycyphal.transport

__all__ = [
    "CAN_CLASSIC_MTU",
    "CAN_FD_MTU",
    "TRANSPORT_KINDS",
    "TransportConfigError",
    "aclose",
    "make_node",
    "make_node_from_env",
    "make_transport",
    "quiet_late_media_completions",
    "transport_from_env",
]

_log = logging.getLogger(__name__)

TRANSPORT_KINDS = ("udp", "can", "loopback")
CAN_CLASSIC_MTU = 8
CAN_FD_MTU = 64
_CAN_MTUS = (8, 12, 16, 20, 24, 32, 48, 64)
_CAN_BITRATE_CLASSIC = 1_000_000
_CAN_BITRATE_FD = (1_000_000, 4_000_000)
_DEFAULT_UDP_IFACE = "127.0.0.1"
_MAX_NODE_ID = {"udp": 65534, "can": 127, "loopback": 65534}


class TransportConfigError(ValueError):
    """The arguments or environment do not describe a usable transport."""


def _check_node_id(kind: str, node_id: int | None) -> None:
    if node_id is None:
        return
    if not isinstance(node_id, int) or isinstance(node_id, bool) or not 0 <= node_id <= _MAX_NODE_ID[kind]:
        raise TransportConfigError(
            f"node-ID {node_id!r} is out of range for {kind} (0..{_MAX_NODE_ID[kind]}, or None for anonymous)"
        )


def _can_media(iface: str, mtu: int) -> Any:
    """Same media rule as pycyphal.application.make_transport: ``socketcan:`` -> pycyphal's native SocketCAN
    media (Linux), anything else (``virtual:NAME``, ``pcan:...``, ``slcan:...``) -> python-can."""
    if mtu not in _CAN_MTUS:
        raise TransportConfigError(f"CAN MTU {mtu} is not one of {_CAN_MTUS} (8 = Classic CAN, 64 = CAN FD)")
    if ":" not in iface:
        raise TransportConfigError(
            f"CAN iface {iface!r} must be 'interface:channel', e.g. 'virtual:vcan0' or 'socketcan:can0'"
        )
    if iface.lower().startswith("socketcan:"):
        from pycyphal.transport.can.media.socketcan import SocketCANMedia

        return SocketCANMedia(iface.split(":", 1)[1], mtu=mtu)
    from pycyphal.transport.can.media.pythoncan import PythonCANMedia

    bitrate: int | tuple[int, int] = _CAN_BITRATE_CLASSIC if mtu == CAN_CLASSIC_MTU else _CAN_BITRATE_FD
    return PythonCANMedia(iface, bitrate, mtu)


def make_transport(
    kind: str,
    *,
    node_id: int | None,
    iface: str | None = None,
    mtu: int | None = None,
    loop_rx: bool = False,
) -> pycyphal.transport.Transport:
    """A pycyphal transport.

    :param kind: ``"udp"``, ``"can"`` or ``"loopback"``.
    :param node_id: local node-ID, or None for an anonymous (listen-mostly) transport.
        UDP 0..65534, CAN 0..127.
    :param iface: UDP: local IPv4 address of the interface (default ``127.0.0.1``).
        CAN: ``interface:channel``, e.g. ``virtual:vcan0`` (python-can in-process virtual bus; all
        transports on the same channel name in one process see each other) or ``socketcan:can0``.
        Several whitespace-separated ifaces give a RedundantTransport. Unused for loopback.
    :param mtu: UDP: payload bytes per datagram (pycyphal default 1200). CAN: 8 = Classic CAN,
        64 (default) = CAN FD; 12..48 are CAN FD too.
    :param loop_rx: UDP on one interface: a transport whose message subscriptions can be received on the event
        loop instead of pycyphal's thread per session (sam_runtime.cyphal_io.udp_receiver.loop_udp_transport), and
        whose pycyphal input sessions (services, the heartbeat publisher's, the object path's subjects) are received
        on the loop too (sam_runtime.cyphal_io.udp_sessions.loop_sessions_udp_transport).
    """
    kind = kind.lower().strip()
    if kind not in TRANSPORT_KINDS:
        raise TransportConfigError(f"unknown transport kind {kind!r}; expected one of {TRANSPORT_KINDS}")
    _check_node_id(kind, node_id)
    if kind == "loopback":
        from pycyphal.transport.loopback import LoopbackTransport

        return LoopbackTransport(node_id)
    import pycyphal.transport

    factories: list[Callable[[], pycyphal.transport.Transport]] = []
    if kind == "udp":
        from pycyphal.transport.udp import UDPTransport

        kw: dict[str, Any] = {} if mtu is None else {"mtu": int(mtu)}
        ips = (iface or _DEFAULT_UDP_IFACE).split()
        make_udp: Callable[..., pycyphal.transport.Transport] = UDPTransport
        if loop_rx and len(ips) == 1:
            make_udp = loop_sessions_udp_transport
        for ip in ips:
            factories.append(functools.partial(make_udp, ip, node_id, **kw))
    else:
        from pycyphal.transport.can import CANTransport

        if not iface:
            raise TransportConfigError("CAN transport needs iface, e.g. 'virtual:vcan0' or 'socketcan:can0'")
        eff_mtu = CAN_FD_MTU if mtu is None else int(mtu)
        for name in iface.split():
            def can(name: str = name) -> pycyphal.transport.Transport:
                return CANTransport(_can_media(name, eff_mtu), node_id)

            factories.append(can)
    inferiors: list[pycyphal.transport.Transport] = []
    try:
        for f in factories:
            inferiors.append(f())
    except (ValueError, OSError, pycyphal.transport.InvalidMediaConfigurationError) as ex:
        for t in inferiors:
            t.close()
        if isinstance(ex, TransportConfigError):
            raise
        raise TransportConfigError(
            f"cannot open {kind} transport on {iface!r}: {type(ex).__name__}: {ex}"
        ) from ex
    except BaseException:
        for t in inferiors:
            t.close()
        raise
    if len(inferiors) == 1:
        return inferiors[0]
    from pycyphal.transport.redundant import RedundantTransport

    red = RedundantTransport()
    for t in inferiors:
        red.attach_inferior(t)
    return red


def _ensure_uavcan() -> None:
    """pycyphal.application imports the whole compiled ``uavcan`` namespace: make sure it is importable."""
    import sys

    if "uavcan" not in sys.modules and find_compiled("uavcan") is None:
        ensure_compiled(())


def _registry(environ: Mapping[str, str] | None) -> Any:
    import pycyphal.application

    # make_registry(None, ...) keeps every register in memory; it never writes a file.
    env = {} if environ is None else {str(k): str(v) for k, v in environ.items()}
    return pycyphal.application.make_registry(None, environment_variables=env)


def transport_from_env(env: Mapping[str, str] | None = None, *, loop_rx: bool = False) -> pycyphal.transport.Transport:
    """A transport configured by the standard register environment variables (default: ``os.environ``).

    UAVCAN__NODE__ID (absent or 65535 = anonymous), UAVCAN__UDP__IFACE (space-separated IPs),
    UAVCAN__UDP__MTU, UAVCAN__CAN__IFACE (e.g. ``virtual:vcan0`` or ``socketcan:can0``), UAVCAN__CAN__MTU
    (8 or 64; default 64), UAVCAN__CAN__BITRATE ('1000000 1000000' for Classic CAN), UAVCAN__LOOPBACK=1,
    UAVCAN__SERIAL__IFACE. Several configured transports give a RedundantTransport.
    Needs the compiled ``uavcan`` namespace (it is compiled on demand).
    ``loop_rx``: one UDP interface gives a loop_sessions_udp_transport (see :func:`make_transport`), configured as
    pycyphal's.
    """
    _ensure_uavcan()
    import pycyphal.application
    from pycyphal.transport.udp import UDPTransport

    env = os.environ if env is None else env
    env = dict(_classic_can_bitrate_default(env))
    registry = _registry(env)
    tr = pycyphal.application.make_transport(registry)
    if tr is None:
        raise TransportConfigError(
            "no transport configured: set UAVCAN__UDP__IFACE (e.g. 127.0.0.1), UAVCAN__CAN__IFACE "
            "(e.g. virtual:vcan0) or UAVCAN__LOOPBACK=1"
        )
    if loop_rx and type(tr) is UDPTransport:  # pycyphal built it from the registers, which give its settings
        multiplier = int(registry["uavcan.udp.duplicate_service_transfers"]) + 1
        ip, node_id, mtu = tr.local_ip_address, tr.local_node_id, tr.protocol_parameters.mtu
        tr.close()  # no session opened yet: nothing else to undo
        tr = loop_sessions_udp_transport(str(ip), node_id, mtu=mtu, service_transfer_multiplier=multiplier)
    return tr


def _classic_can_bitrate_default(env: Mapping[str, str]) -> Mapping[str, str]:
    """pycyphal defaults uavcan.can.bitrate to (1M, 4M): with MTU 8 that makes an FD bus with 8-byte frames.
    When MTU 8 is asked for without a bitrate, select real Classic CAN (equal bitrates)."""
    mtu = str(env.get("UAVCAN__CAN__MTU", "")).strip()
    if mtu == "8" and not str(env.get("UAVCAN__CAN__BITRATE", "")).strip():
        out = dict(env)
        out["UAVCAN__CAN__BITRATE"] = f"{_CAN_BITRATE_CLASSIC} {_CAN_BITRATE_CLASSIC}"
        return out
    return env


def _node_info(name: str, version: Sequence[int], unique_id: bytes | None) -> Any:
    import pycyphal.application
    import uavcan.node

    if not name or len(name.encode()) > 50:
        raise TransportConfigError(
            f"node name {name!r} must be 1..50 bytes (reverse-domain, e.g. org.sam.bridge)"
        )
    major, minor = (*version, 0, 0)[:2]
    info = pycyphal.application.NodeInfo(
        name=name,
        software_version=uavcan.node.Version_1(major=major, minor=minor),
    )
    if unique_id is not None:
        if len(unique_id) != 16:
            raise TransportConfigError("unique_id must be 16 bytes")
        info.unique_id = unique_id
    return info


def make_node(
    name: str,
    node_id: int | None,
    kind: str = "udp",
    *,
    iface: str | None = None,
    mtu: int | None = None,
    transport: pycyphal.transport.Transport | None = None,
    version: Sequence[int] = (0, 1),
    unique_id: bytes | None = None,
    environ: Mapping[str, str] | None = None,
    start: bool = True,
    dsdl_dirs: Sequence[Path] = (),
) -> pycyphal.application.Node:
    """A pycyphal.application node (heartbeat, GetInfo, register service) on an explicit transport.

    :param name: GetInfo name, reverse-domain style (``org.sam.bridge``), at most 50 bytes.
    :param node_id, kind, iface, mtu: see :func:`make_transport` (ignored when ``transport`` is given;
        the node takes ownership of ``transport`` and closes it).
    :param environ: register overrides as UAVCAN__* environment variables (e.g. port-ID registers
        ``UAVCAN__PUB__IMU__ID``); default: none - the process environment is NOT consulted.
    :param start: start the heartbeat publisher and the other application functions now.
    :param dsdl_dirs: extra root namespaces to compile with uavcan if uavcan is not importable yet
        (so both end up in one cache entry); see :func:`sam_runtime.cyphal_io.dsdl_cache.ensure_compiled`.
    The registry lives in memory only: nothing is written to the repository or the working directory.
    A random unique-ID is drawn per launch unless ``unique_id`` is given.
    """
    if dsdl_dirs:
        ensure_compiled(dsdl_dirs)
    else:
        _ensure_uavcan()
    import pycyphal.application

    info = _node_info(name, version, unique_id)
    registry = _registry(environ)
    if transport is None:
        transport = make_transport(kind, node_id=node_id, iface=iface, mtu=mtu)
    try:
        node = pycyphal.application.make_node(info, registry, transport=transport)
    except BaseException:
        transport.close()
        raise
    if start:
        node.start()
    return node


def make_node_from_env(
    name: str,
    env: Mapping[str, str] | None = None,
    *,
    version: Sequence[int] = (0, 1),
    unique_id: bytes | None = None,
    start: bool = True,
) -> pycyphal.application.Node:
    """A node whose transport, node-ID and port-IDs come from UAVCAN__* variables (default ``os.environ``),
    via pycyphal.application.make_node's own register handling; in-memory registry, no file written."""
    _ensure_uavcan()
    import pycyphal.application

    env = os.environ if env is None else env
    info = _node_info(name, version, unique_id)
    registry = _registry(_classic_can_bitrate_default(env))
    try:
        node = pycyphal.application.make_node(info, registry)
    except pycyphal.application.register.MissingRegisterError as ex:
        registry.close()
        raise TransportConfigError(
            f"{ex}: set UAVCAN__UDP__IFACE (e.g. 127.0.0.1), UAVCAN__CAN__IFACE (e.g. virtual:vcan0) "
            "or UAVCAN__LOOPBACK=1"
        ) from None
    if start:
        node.start()
    return node


async def aclose(*closables: Any, timeout: float = 2.0) -> None:
    """Close nodes/transports/presentations and wait (deadline-bounded) until pycyphal's background tasks end.

    ``close()`` alone is synchronous and leaves pycyphal's subscriber/server tasks to notice on their own,
    which can take up to their 1 s receive timeout: on Python 3.11 a cancellation that arrives while such a
    task sits in ``asyncio.wait_for`` can be lost. Here the still-running pycyphal tasks of closed objects are
    cancelled again and awaited, so nothing outlives the call (no "Task was destroyed but it is pending").
    Only those: the tasks of other nodes and ports that live on in the same loop (a bridge and simulated
    devices in one process, a node being reopened) are left alone.
    Call it from inside the event loop that created the objects.
    """
    me = asyncio.current_task()
    before = {t for t in asyncio.all_tasks() if t is not me and not t.done()}
    for c in closables:
        if c is not None:
            c.close()
    await asyncio.sleep(0)  # let the cancellations issued by close() be delivered
    loop = asyncio.get_running_loop()
    deadline = loop.time() + timeout
    while True:
        pending = [t for t in before if not t.done() and _is_pycyphal_task(t) and _owner_closed(t)]
        if not pending or loop.time() >= deadline:
            break
        for t in pending:
            t.cancel()
        await asyncio.wait(pending, timeout=min(0.05, max(0.0, deadline - loop.time())))


def _is_pycyphal_task(task: asyncio.Task[Any]) -> bool:
    code = getattr(task.get_coro(), "cr_code", None)
    return code is not None and f"{os.sep}pycyphal{os.sep}" in code.co_filename


def _owner_closed(task: asyncio.Task[Any]) -> bool:
    """Whether the pycyphal object running the task (``self`` of its coroutine: a Subscriber, SubscriberImpl,
    Server, Client, HeartbeatPublisher, ...) has been closed. Unknown owners count as not closed."""
    frame = getattr(task.get_coro(), "cr_frame", None)
    owner = None if frame is None else frame.f_locals.get("self")
    if owner is None:
        return False
    for attr in ("_closed", "is_closed"):
        try:
            value = getattr(owner, attr, None)
        except Exception:
            continue
        if isinstance(value, bool):
            return value
    if "_maybe_task" in getattr(owner, "__dict__", {}):  # HeartbeatPublisher: the task is dropped on close
        return owner._maybe_task is None
    return False


def quiet_late_media_completions(loop: asyncio.AbstractEventLoop) -> None:
    """pycyphal's python-can media completes a frame's future from its TX thread with call_soon_threadsafe;
    when the awaiting task was cancelled meanwhile (a node closing, a send deadline), ``set_result`` on the
    cancelled future raises InvalidStateError inside the loop, which asyncio prints as a traceback. Those are
    harmless: log them at DEBUG level. Installed only when the loop has no exception handler of its own."""
    if loop.get_exception_handler() is not None:
        return

    def handler(lp: asyncio.AbstractEventLoop, context: dict[str, Any]) -> None:
        exc = context.get("exception")
        if isinstance(exc, asyncio.InvalidStateError) and "set_" in repr(context.get("handle", "")):
            _log.debug("late completion of a cancelled Cyphal media future: %s", context.get("handle"))
            return
        lp.default_exception_handler(context)

    loop.set_exception_handler(handler)
