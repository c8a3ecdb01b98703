"""USD export: the baked clip as a UsdSkel skinned mesh (``.usda`` text, ``.usdc`` or ``.usd``
binary), the same skeleton, skin and keys as the glTF export (:mod:`treeanim.export`).

The stage holds one ``SkelRoot`` (``/<tree>``, the default prim) with a ``Skeleton`` whose
joints are named by their path down the hierarchy (``j0/j3/j7``), a ``SkelAnimation`` of their
rotations, one key per frame (time code = frame, ``timeCodesPerSecond`` = the frame rate), and a
``Mesh`` bound to it with four joint influences per vertex. Y is up, one unit is a metre.
USD (``usd-core``) is an optional dependency: ``pip install 'treeanim[usd]'``.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from .errors import InputError
from .export import Skeleton, check_joints, rest_joints, rest_translations, skeleton, skin, vertex_colours
from .files import atomic_path
from .model.tree import Tree
from .render.mesh import TreeMesh, build_mesh

__all__ = ["USD_SUFFIXES", "joint_paths", "require_usd", "write_usd"]

#: The file endings the USD export writes (the format follows the ending; ``.usd`` is binary).
USD_SUFFIXES = (".usd", ".usda", ".usdc")


def require_usd():
    """The USD modules, or :class:`~treeanim.errors.InputError` (one line, what to install) when
    usd-core is not installed."""
    try:
        from pxr import Gf, Sdf, Usd, UsdGeom, UsdSkel, Vt
    except ImportError:
        raise InputError("USD export needs usd-core: pip install 'treeanim[usd]' (or write .glb)") from None
    return Gf, Sdf, Usd, UsdGeom, UsdSkel, Vt


def joint_paths(skel: Skeleton) -> list[str]:
    """Each joint's name as UsdSkel orders them: its path from the root joint, ``j0/j3/j7``.

    A joint's parent comes before it (:func:`~treeanim.export.skeleton` numbers them so), so
    one pass in joint order builds every path from its parent's.
    """
    paths: list[str] = []
    for j, p in enumerate(skel.joint_parent.tolist()):
        paths.append(f"j{j}" if p < 0 else f"{paths[p]}/j{j}")
    return paths


def _prim_name(name: str) -> str:
    """A valid USD prim name from a tree's name."""
    name = re.sub(r"[^A-Za-z0-9_]", "_", name) or "tree"
    return name if not name[0].isdigit() else f"_{name}"


def write_usd(path: str | Path, tree: Tree, keys: np.ndarray, fps: float, season: float = 0.0,
              mesh: TreeMesh | None = None, present: np.ndarray | None = None,
              skel: Skeleton | None = None) -> list[Path]:
    """Write the clip to a USD file atomically; returns ``[path]``.

    Parameters
    ----------
    path : str or Path
        ``.usda`` (text), ``.usdc`` or ``.usd`` (binary crate).
    tree, keys, fps, season, mesh, present, skel
        As :func:`treeanim.export.build_gltf` takes them: ``keys`` (F, J, 4) are the joints'
        local rotations (x, y, z, w), key k at time code k.

    Raises
    ------
    ValueError
        If usd-core is missing, or ``keys`` are not for the skeleton's joints.
    """
    Gf, Sdf, Usd, UsdGeom, UsdSkel, Vt = require_usd()
    path = Path(path)
    mesh = mesh if mesh is not None else build_mesh(tree)
    skel = skel if skel is not None else skeleton(tree, present)
    if keys.shape[1] != skel.count:
        raise ValueError(f"keys for {keys.shape[1]} joints, the skeleton has {skel.count}")
    check_joints(skel)
    keep_tris, used, pos, joints, weights = skin(tree, mesh, skel, present)

    stage = Usd.Stage.CreateInMemory()
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.y)
    UsdGeom.SetStageMetersPerUnit(stage, 1.0)
    stage.SetTimeCodesPerSecond(fps)
    stage.SetFramesPerSecond(fps)
    stage.SetStartTimeCode(0)
    stage.SetEndTimeCode(len(keys) - 1)
    stage.GetRootLayer().documentation = f"{tree.name}: baked by treeanim"
    root_path = Sdf.Path("/" + _prim_name(tree.name))
    root = UsdSkel.Root.Define(stage, root_path)
    stage.SetDefaultPrim(root.GetPrim())

    # --- the skeleton: rest (local) and bind (world) transforms; at rest every frame is
    # axis-aligned, so both are translations
    rest = rest_joints(tree, skel)
    J = skel.count
    local = np.tile(np.eye(4), (J, 1, 1))
    local[:, 3, :3] = rest_translations(tree, skel)  # USD's matrices are row-vector: translation in row 3
    bind = np.tile(np.eye(4), (J, 1, 1))
    bind[:, 3, :3] = rest
    skeleton_prim = UsdSkel.Skeleton.Define(stage, root_path.AppendChild("Skeleton"))
    names = joint_paths(skel)
    skeleton_prim.CreateJointsAttr(names)
    skeleton_prim.CreateRestTransformsAttr(Vt.Matrix4dArray.FromNumpy(local))
    skeleton_prim.CreateBindTransformsAttr(Vt.Matrix4dArray.FromNumpy(bind))

    # --- the animation: constant translations and scales, a rotation key per frame
    anim = UsdSkel.Animation.Define(stage, skeleton_prim.GetPath().AppendChild("Wind"))
    anim.CreateJointsAttr(names)
    anim.CreateTranslationsAttr(Vt.Vec3fArray.FromNumpy(local[:, 3, :3].astype(np.float32)))
    anim.CreateScalesAttr(Vt.Vec3hArray.FromNumpy(np.ones((J, 3), np.float16)))
    rotations = anim.CreateRotationsAttr()
    for k, q in enumerate(np.asarray(keys, np.float32)):
        rotations.Set(Vt.QuatfArray.FromNumpy(np.ascontiguousarray(q)), float(k))
    UsdSkel.BindingAPI.Apply(skeleton_prim.GetPrim()).CreateAnimationSourceRel().SetTargets([anim.GetPath()])

    # --- the mesh, bound to the skeleton
    remap = np.cumsum(used) - 1
    index = remap[mesh.indices[keep_tris]].astype(np.int32)
    v = mesh.vertices[used]
    nrm = v["normal"].astype(np.float64)
    nrm /= np.linalg.norm(nrm, axis=1, keepdims=True)
    geom = UsdGeom.Mesh.Define(stage, root_path.AppendChild("Mesh"))
    geom.CreatePointsAttr(Vt.Vec3fArray.FromNumpy(pos))
    geom.CreateFaceVertexCountsAttr(Vt.IntArray.FromNumpy(np.full(len(index), 3, np.int32)))
    geom.CreateFaceVertexIndicesAttr(Vt.IntArray.FromNumpy(index.ravel()))
    geom.CreateNormalsAttr(Vt.Vec3fArray.FromNumpy(nrm.astype(np.float32)))
    geom.SetNormalsInterpolation(UsdGeom.Tokens.vertex)
    geom.CreateSubdivisionSchemeAttr(UsdGeom.Tokens.none)
    geom.CreateDoubleSidedAttr(True)
    geom.CreateExtentAttr(Vt.Vec3fArray.FromNumpy(np.array([pos.min(0), pos.max(0)], np.float32)))
    colour = vertex_colours(tree, mesh, season)[used][:, :3].astype(np.float32)
    geom.CreateDisplayColorPrimvar(UsdGeom.Tokens.vertex).Set(Vt.Vec3fArray.FromNumpy(colour))
    binding = UsdSkel.BindingAPI.Apply(geom.GetPrim())
    binding.CreateSkeletonRel().SetTargets([skeleton_prim.GetPath()])
    binding.CreateJointIndicesPrimvar(False, 4).Set(Vt.IntArray.FromNumpy(joints.astype(np.int32).ravel()))
    binding.CreateJointWeightsPrimvar(False, 4).Set(Vt.FloatArray.FromNumpy((weights / 255.0).astype(np.float32).ravel()))
    binding.CreateGeomBindTransformAttr().Set(Gf.Matrix4d(1.0))

    with atomic_path(path, suffix=path.suffix.lower()) as tmp:
        if not stage.GetRootLayer().Export(str(tmp)):
            raise OSError(f"USD could not write {tmp}")
    return [path]
