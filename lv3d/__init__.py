"""lv3d: learn 3D shape concepts from very few RGB-D images, and explain every answer."""

__version__ = "0.1.0"
