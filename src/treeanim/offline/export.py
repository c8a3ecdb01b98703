"""``treeanim export``: the simulated motion baked into a glTF 2.0 or USD file (keys on a
skeleton), or a static glTF for shader wind (:mod:`treeanim.shader_wind`)."""

from __future__ import annotations

from .. import options as opt
from ..errors import UsageError


def _check_frames(args) -> int:
    """The clip's frame count n (n + 1 keys), or a one-line refusal."""
    n = opt.check_frames(args.seconds, args.fps)
    if abs(args.seconds * args.fps - n) > 1e-6 * max(n, 1):
        whole = sorted({max(int(args.seconds * args.fps), 1), int(args.seconds * args.fps) + 1})
        raise UsageError(f"--seconds {args.seconds:g} at --fps {args.fps:g} is {args.seconds * args.fps:.4g} frames; a clip "
                         f"holds whole frames: try --seconds {' or '.join(f'{k / args.fps:.6g}' for k in whole)}")
    if n < 2:
        raise UsageError(f"--seconds {args.seconds:g} at --fps {args.fps:g} gives fewer than 2 frames")
    return n


def cmd_export(args) -> int:
    """Bake the simulated motion into a glTF 2.0 or USD file: n frames at --fps make n + 1 keys,
    the last at exactly --seconds (a loop's repeats its first: :mod:`treeanim.loop`); or, with
    ``--motion shader``, write the static mesh with the shader-wind attributes."""
    from .. import compact, export, export_usd, joints, loop
    from ..render.mesh import build_mesh

    if args.motion == "shader":
        return _shader_export(args)
    if args.instances is not None:
        raise UsageError("--instances: only a shader-wind mesh is instanced (add --motion shader)")
    out = opt.output_path(args.out, (".glb", ".gltf", *export_usd.USD_SUFFIXES))
    usd = out.suffix.lower() in export_usd.USD_SUFFIXES
    if usd:
        export_usd.require_usd()
    n = _check_frames(args)
    fade = max(opt.check_frames(args.loop, args.fps), 1) if args.loop > 0 else 0
    if fade >= n:
        raise UsageError(f"--loop {args.loop:g}: the cross-fade must be shorter than --seconds")
    budget = args.joints if args.target is None else opt.JOINT_TARGETS[args.target]
    tree, sim = opt.make_simulation(args)
    skel = export.skeleton(tree, sim.present)
    try:
        raw = export.bake(sim, skel, n + max(fade, 1), args.fps, opt.scheduled(args), quiet=args.quiet)
    except ValueError as e:
        raise UsageError(str(e)) from None
    full = skel
    mesh = build_mesh(tree) if usd else compact.card_mesh(tree)  # once, for the fit, the file and its error
    skel, raw, error = joints.fit(tree, full, raw, n, budget, sim.present, mesh)
    keys = loop.close_loop(raw, n) if fade else raw
    packed = args.precision == "compact" and not usd
    skinned = export.skin(tree, mesh, skel, sim.present)[2:] if packed else None
    encoded = compact.encode(tree, skel, keys, *skinned[:2]) if packed else None  # once, for the file and its error
    if usd:
        files = export_usd.write_usd(out, tree, keys, args.fps, season=args.season, mesh=mesh, present=sim.present, skel=skel)
    else:
        doc, data = export.build_gltf(tree, keys, args.fps, season=args.season, mesh=mesh, present=sim.present, skel=skel,
                                      precision=args.precision, encoded=encoded)
        files = export.write_gltf(out, doc, data)
    size = sum(f.stat().st_size for f in files)
    print(f"wrote {', '.join(map(str, files))}: {skel.count} joints, {n} frames at {args.fps:g} fps, "
          f"{n + 1} keys from 0 to {n / args.fps:.2f} s, {size / 1e6:.1f} MB")
    print(joints.report(full, skel, budget, error))
    if packed:
        print(compact.report(compact.error(tree, skel, keys, *skinned, encoded=encoded)))
    if fade:
        print(loop.seam(keys, raw).line())
    return 0


def _shader_export(args) -> int:
    """``--motion shader``: measure the branches in the simulation, write the static glTF."""
    from .. import export, shader_wind

    out = opt.output_path(args.out, (".glb", ".gltf"))
    clashing = [name for name, on in (("--loop", args.loop > 0), ("--joints", args.joints is not None),
                                      ("--target", args.target is not None)) if on]
    if clashing:
        raise UsageError(f"{', '.join(clashing)}: a shader-wind mesh has no keys or joints (--motion shader)")
    tree = opt.load_any(args.preset, args)
    if args.instances is not None:
        return _instanced_export(args, out, tree)
    table = shader_wind.branch_table(tree, season=args.season)
    doc, data = shader_wind.build_shader_gltf(tree, table, season=args.season)
    files = export.write_gltf(out, doc, data)
    size = sum(f.stat().st_size for f in files)
    print(f"wrote {', '.join(map(str, files))}: a static mesh for shader wind, {shader_wind.LEVELS} levels of "
          f"branches per vertex, measured in {2 * shader_wind.SETTLE + shader_wind.RING:g} s of simulation (bends grow "
          f"as U^{table.exponent:.2f}); {size / 1e6:.1f} MB (sway it with shaders/engine_wind.glsl)")
    return 0


def template_seeds(placements, k: int) -> dict[tuple, list[int]]:
    """Per tree source (a preset or file, and a TreeQSM model's leaves) of a scene's
    ``placements``: the seeds of its ``k`` templates, the first ``k`` distinct seeds of its
    trees in scene order."""
    seeds: dict[tuple, list[int]] = {}
    for p in placements:
        own = seeds.setdefault((p.tree, p.leaves), [])
        if len(own) < k and p.seed not in own:
            own.append(p.seed)
    return seeds


def template_of(seeds: list[int], seed: int) -> int:
    """The template a tree of ``seed`` takes among its source's template ``seeds``: its own
    where it is one, else seed mod their count."""
    return seeds.index(seed) if seed in seeds else seed % len(seeds)


def _instanced_export(args, out, scene) -> int:
    """``--motion shader --instances K``: a scene as instances of K templates per tree source."""
    from .. import export, shader_wind
    from ..model.scene import Scene
    from ..model.scene_file import grow_placed

    if not isinstance(scene, Scene) or scene.n_trees < 2:
        raise UsageError(f"--instances: {args.preset} is a single tree; instances are for scenes")
    templates, where = [], []
    for source, seeds in template_seeds(scene.placements, args.instances).items():
        placed = [p for p in scene.placements if (p.tree, p.leaves) == source]
        for j, seed in enumerate(seeds):
            first = next(p for p in placed if p.seed == seed)
            tree = opt.with_settings(grow_placed(scene, first), args)
            templates.append((tree, shader_wind.branch_table(tree, season=args.season)))
            where.append([p for p in placed if template_of(seeds, p.seed) == j])
    doc, data = shader_wind.build_instanced_gltf(scene.name, templates, where, season=args.season)
    files = export.write_gltf(out, doc, data)
    size = sum(f.stat().st_size for f in files)
    print(f"wrote {', '.join(map(str, files))}: {scene.n_trees} trees as instances of {len(templates)} shader-wind "
          f"templates ({', '.join(sorted({p.tree for p in scene.placements}))}); {size / 1e6:.1f} MB (sway them "
          "with shaders/engine_wind.glsl)")
    return 0
