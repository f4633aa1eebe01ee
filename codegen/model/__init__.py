"""The data every stage shares: the spec model (spec), the type system (types), the error model (diagnostics) and
the names the generator and the runtime both derive from the spec (names).

The bottom layer of sam_codegen: it imports nothing else of the package. Every class is frozen: the frontend builds
the model whole, and nothing changes it after.
"""

from sam_codegen.model.diagnostics import NOWHERE as NOWHERE
from sam_codegen.model.diagnostics import Diagnostic as Diagnostic
from sam_codegen.model.diagnostics import Pos as Pos
from sam_codegen.model.diagnostics import SpecError as SpecError
from sam_codegen.model.names import ros_parameter_name as ros_parameter_name
from sam_codegen.model.spec import ROS_TO_UAVCAN as ROS_TO_UAVCAN
from sam_codegen.model.spec import UAVCAN_TO_ROS as UAVCAN_TO_ROS
from sam_codegen.model.spec import Bridge as Bridge
from sam_codegen.model.spec import Constant as Constant
from sam_codegen.model.spec import Device as Device
from sam_codegen.model.spec import Direction as Direction
from sam_codegen.model.spec import DsdlStruct as DsdlStruct
from sam_codegen.model.spec import Field as Field
from sam_codegen.model.spec import Mapping as Mapping
from sam_codegen.model.spec import Node as Node
from sam_codegen.model.spec import Qos as Qos
from sam_codegen.model.spec import RosMessage as RosMessage
from sam_codegen.model.spec import Spec as Spec
from sam_codegen.model.spec import Topic as Topic
from sam_codegen.model.spec import V0Struct as V0Struct
from sam_codegen.model.types import DsdlType as DsdlType
from sam_codegen.model.types import RosType as RosType
