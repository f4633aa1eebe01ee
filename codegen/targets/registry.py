"""Every target's emitter, in the order build runs them (the order only decides which error is reported first;
the outputs are disjoint)."""

from __future__ import annotations

from collections.abc import Callable

from sam_codegen.targets import docs, dsdl, dsdl_v0, firmware, nodes, ros
from sam_codegen.targets.python import convert, convert_v0
from sam_codegen.targets.python import services as python_services
from sam_codegen.targets.wire import codec, codec_v0
from sam_codegen.validate import Resolved

Emitter = Callable[[Resolved], dict[str, str]]

EMITTERS: tuple[Emitter, ...] = (ros.emit, dsdl.emit, dsdl_v0.emit, convert.emit, convert_v0.emit, nodes.emit,
                                 docs.emit, codec.emit, codec_v0.emit, python_services.emit,
                                 firmware.emit)
