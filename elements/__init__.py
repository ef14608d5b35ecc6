"""Element library (``vtsi.elements``): importing it registers every shipped element type."""
from .base import ELEMENT_TYPES, ElementType, element_type, register
from .beam_column import ElasticBeamColumn2d

__all__ = ["ELEMENT_TYPES", "ElementType", "element_type", "register", "ElasticBeamColumn2d"]
