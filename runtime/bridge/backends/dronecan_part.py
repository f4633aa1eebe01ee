"""DroneCAN's part of a bridge (sam_runtime.bridge.backends.part.BridgePart), registered in sam_runtime.protocols.
The backend's module imports dronecan: it is imported when a DroneCAN bridge starts, not before."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from types import ModuleType
from typing import Any

from sam_runtime.bridge.backend import Backend
from sam_runtime.bridge.backends.dronecan_duties import DroneCanDuties
from sam_runtime.bridge.backends.dronecan_services import DroneCanServices
from sam_runtime.bridge.backends.interface_ask import dronecan_ask
from sam_runtime.bridge.backends.param_access import DroneCanParamAccess, ParamAccess
from sam_runtime.bridge.backends.part import BackendSettings
from sam_runtime.bridge.backends.service_mappings import ServiceMappingsRos
from sam_runtime.bridge.backends.time_sync_messages import SyncMessage, dronecan_sync_message
from sam_runtime.bridge.interface_check import Ask
from sam_runtime.bridge.lifetime import Lifetime
from sam_runtime.genpkg import GeneratedPackage

__all__ = ["PART", "DroneCanPart"]


class DroneCanPart:
    def backend(self, settings: BackendSettings) -> Backend:
        from sam_runtime.bridge.backends.dronecan import DroneCanBackend  # needs dronecan (the runtime extra)

        return DroneCanBackend(settings.dronecan_iface, settings.node_id, rlog=settings.rlog, errors=settings.errors,
                               name=settings.name)

    def converters(self, gen: GeneratedPackage) -> ModuleType:
        return gen.convert_v0()  # loads the spec's v0 types into dronecan first

    def duties(self, lifetime: Lifetime, backend: Backend, ros: Any, devices: Mapping[int, str], tables: Any,
               options: Mapping[str, Any]) -> Any:
        # the spec's `panic_duty: mappings` turns the built-in Panic duty off
        duties = DroneCanDuties(lifetime, backend, ros, devices,
                                **{"panic": tables.DRONECAN_PANIC_DUTY != "mappings", **options})
        duties.attach()
        return duties

    def services(self, lifetime: Lifetime, backend: Backend, ros: Any, mappings: Sequence[Any], *,
                 diagnostics_period: float) -> ServiceMappingsRos:
        return DroneCanServices(lifetime, backend, ros, mappings, diagnostics_period=diagnostics_period)

    def param_access(self, backend: Backend) -> ParamAccess:
        return DroneCanParamAccess(backend)

    def sync_message(self) -> SyncMessage:
        return dronecan_sync_message()

    def prepare_replay(self, gen: GeneratedPackage) -> None:
        pass  # the v0 codecs read the payload bytes with the spec's own layouts

    def interface_ask(self, backend: Backend) -> Ask:
        return dronecan_ask(backend)


PART = DroneCanPart()
