"""Rendering core: skinned tree meshes, the moderngl renderer, camera, picking, overlays and
headless (EGL) rendering. Shared by the viewer, the offline renderer and the glTF exporter.

Names are imported lazily (``from treeanim.render import Renderer``), so importing one
GL-free module (e.g. ``treeanim.render.mesh``) does not pull in the others.
"""

from treeanim._lazy import lazy_exports

_EXPORTS = {
    "TreeMesh": "mesh",
    "build_mesh": "mesh",
    "Renderer": "renderer",
    "Scene": "renderer",
    "OffscreenRenderer": "offscreen",
    "create_egl_context": "offscreen",
    "OrbitCamera": "camera",
    "Picker": "picking",
    "PickHit": "picking",
    "pick": "picking",
    "Overlay": "overlays",
    "LineSet": "overlays",
    "PullTrace": "overlays",
    "LocalFrames": "overlays",
    "WindSlices": "overlays",
    "WindArrow": "overlays",
}

__all__ = sorted(_EXPORTS)

__getattr__, __dir__ = lazy_exports(__name__, globals(), _EXPORTS)
