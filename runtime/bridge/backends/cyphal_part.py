"""Cyphal's part of a bridge (sam_runtime.bridge.backends.part.BridgePart), registered in sam_runtime.protocols."""

from __future__ import annotations

import asyncio
from collections.abc import Mapping, Sequence
from types import ModuleType
from typing import Any

from sam_runtime.bridge.backend import Backend
from sam_runtime.bridge.backends.cyphal import CyphalBackend
from sam_runtime.bridge.backends.cyphal_services import CyphalServices
from sam_runtime.bridge.backends.interface_ask import cyphal_ask
from sam_runtime.bridge.backends.param_access import CyphalParamAccess, ParamAccess
from sam_runtime.bridge.backends.part import BackendSettings
from sam_runtime.bridge.backends.service_mappings import ServiceMappingsRos
from sam_runtime.bridge.backends.time_sync_messages import SyncMessage, cyphal_sync_message
from sam_runtime.bridge.interface_check import Ask
from sam_runtime.bridge.lifetime import Lifetime
from sam_runtime.cyphal_io.transport import quiet_late_media_completions
from sam_runtime.genpkg import GeneratedPackage

__all__ = ["PART", "CyphalPart"]


class CyphalPart:
    def backend(self, settings: BackendSettings) -> Backend:
        return CyphalBackend(settings.name, settings.node_id, settings.transport, rlog=settings.rlog,
                             errors=settings.errors, rx_queue_size=settings.rx_queue_size)

    def converters(self, gen: GeneratedPackage) -> ModuleType:
        quiet_late_media_completions(asyncio.get_running_loop())
        return gen.convert()  # compiles the DSDL first (before uavcan/pycyphal.application)

    def duties(self, lifetime: Lifetime, backend: Backend, ros: Any, devices: Mapping[int, str], tables: Any,
               options: Mapping[str, Any]) -> Any:
        return None  # a Cyphal device's duties (GetInfo, ExecuteCommand...) are the spec's node_services

    def services(self, lifetime: Lifetime, backend: Backend, ros: Any, mappings: Sequence[Any], *,
                 diagnostics_period: float) -> ServiceMappingsRos:
        return CyphalServices(lifetime, backend, ros, mappings, diagnostics_period=diagnostics_period)

    def param_access(self, backend: Backend) -> ParamAccess:
        return CyphalParamAccess(backend)

    def sync_message(self) -> SyncMessage:
        return cyphal_sync_message()

    def prepare_replay(self, gen: GeneratedPackage) -> None:
        gen.compile_dsdl()  # the inbound groups name the ports' compiled classes

    def interface_ask(self, backend: Backend) -> Ask:
        return cyphal_ask(backend)


PART = CyphalPart()
