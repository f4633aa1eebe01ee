"""Definitions from outside the spec: ROS messages from the installed share/ folders (ros), Cyphal DSDL from
CYPHAL_PATH (cyphal), the DroneCAN v0 types bundled with dronecan (dronecan).

Layer: above model and project; below validate. Catalogs are independent of each other. A catalog caches what it
reads and changes no model object.
"""

from sam_codegen.catalogs.cyphal import DsdlCatalog as DsdlCatalog
from sam_codegen.catalogs.dronecan import V0Catalog as V0Catalog
from sam_codegen.catalogs.ros import RosCatalog as RosCatalog
