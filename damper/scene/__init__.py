"""Scene files: one analysis a user asks for (TOML), validated once before any work.

``load_scene(path)`` -> :class:`Scene`; the schema (tables, keys, results a scene may
want) is :mod:`damper.scene.schema`; examples in ``examples/scenes/``.
"""
from .load import Scene, SceneError, load_scene, parse_scene, set_path

__all__ = ["Scene", "SceneError", "load_scene", "parse_scene", "set_path"]
