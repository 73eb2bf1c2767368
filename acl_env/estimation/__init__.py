"""Motion estimation (paper section 2.3, Eq. 6), pure numpy: virtual chassis, pole axis, contacts
under the non-slip assumptions and the displacement estimate from kinematics alone."""

from acl_env.estimation.chassis import (
    distance_to_axis,
    helix_axis,
    pole_axis_column,
    to_chassis,
    virtual_chassis,
    winding_axis,
)
from acl_env.estimation.motion import (
    SEA_MODULE_RADIUS,
    MotionEstimate,
    PoleFrame,
    axial_shift,
    contact_joints,
    estimate_displacement,
    estimate_from_frames,
    estimate_gait_cycle,
    locate_on_pole,
)

__all__ = [
    "SEA_MODULE_RADIUS",
    "MotionEstimate",
    "PoleFrame",
    "axial_shift",
    "contact_joints",
    "distance_to_axis",
    "estimate_displacement",
    "estimate_from_frames",
    "estimate_gait_cycle",
    "helix_axis",
    "locate_on_pole",
    "pole_axis_column",
    "to_chassis",
    "virtual_chassis",
    "winding_axis",
]
