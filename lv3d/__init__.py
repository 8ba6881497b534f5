"""lv3d: learn 3D shape concepts from very few RGB-D images, and explain every answer."""

from .workers import in_worker as _in_worker

__version__ = "0.1.0"

_in_worker()  # a worker process started by spawn dies with the process that started it (lv3d.workers)
