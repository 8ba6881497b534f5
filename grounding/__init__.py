"""grounding: refine perceived polygons and planes in JAX (optimistix least squares) and turn their
uncertainty into the confidences of facts. Pure functions over arrays; knows nothing of lv3d."""

from ._cache import enable_cache as enable_cache
from ._calibration import SHARED_SIDE_PREDS as SHARED_SIDE_PREDS
from ._calibration import Calibration as Calibration
from ._calibration import calibrate_with as calibrate_with
from ._calibration import calibration_key as calibration_key
from ._confidence import ACUTE_BELOW_DEG as ACUTE_BELOW_DEG
from ._confidence import CORNER_TURN_MIN_DEG as CORNER_TURN_MIN_DEG
from ._confidence import CORNER_TURN_MIN_PLANE_DEG as CORNER_TURN_MIN_PLANE_DEG
from ._confidence import Confidences as Confidences
from ._confidence import EQUAL_CORNERS_DEG as EQUAL_CORNERS_DEG
from ._confidence import Floors as Floors
from ._confidence import OBTUSE_ABOVE_DEG as OBTUSE_ABOVE_DEG
from ._confidence import PARALLEL_SIDES_DEG as PARALLEL_SIDES_DEG
from ._confidence import PERPENDICULAR_DEG as PERPENDICULAR_DEG
from ._confidence import PLANE_ANGLE_DEG as PLANE_ANGLE_DEG
from ._confidence import RIGHT_ANGLE_DEG as RIGHT_ANGLE_DEG
from ._confidence import SUPPORT_FULL as SUPPORT_FULL
from ._confidence import interval as interval
from ._field import edge_distance_field as edge_distance_field
from ._field import normal_edge_field as normal_edge_field
from ._ground import Grounding as Grounding
from ._ground import fit_plane as fit_plane
from ._ground import ground_object as ground_object
from ._ground import ground_objects as ground_objects
from ._ground import refine_polygon as refine_polygon
from ._problem import MAX_FACES as MAX_FACES
from ._problem import MAX_POINTS as MAX_POINTS
from ._problem import MAX_SIDES as MAX_SIDES
from ._problem import MAX_VERTICES as MAX_VERTICES
from ._problem import ObjectProblem as ObjectProblem
from ._problem import Settings as Settings
from ._problem import pack_object as pack_object
from ._uncertainty import Quantities as Quantities
