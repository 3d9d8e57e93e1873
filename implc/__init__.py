"""implc: compile implicit-surface equations into robust GPU ray-marching shaders."""

__version__ = "0.1.0"
