"""Where a glTF file's bytes go: its buffer views summed per use (each vertex attribute,
triangle indices, animation keys and times, inverse bind matrices, images, other accessors),
with the vertex and triangle counts (a script, not a test).

    python benchmarks/glb_bytes.py FILE.glb [FILE.glb ...]
"""

from __future__ import annotations

import argparse
from collections import Counter

import pygltflib as gl


def uses(doc: gl.GLTF2) -> Counter:
    """Bytes per use of ``doc``'s buffer views (a view shared by several uses counts for the first)."""
    name: dict[int, str] = {}

    def mark(accessor, use):
        if accessor is not None:
            name.setdefault(doc.accessors[accessor].bufferView, use)

    for mesh in doc.meshes:
        for p in mesh.primitives:
            for attr, acc in vars(p.attributes).items():
                mark(acc, attr)
            mark(p.indices, "indices")
    for anim in doc.animations:
        for s in anim.samplers:
            mark(s.output, "keys")
            mark(s.input, "key times")
    for skin in doc.skins:
        mark(skin.inverseBindMatrices, "inverse binds")
    for image in doc.images:
        name.setdefault(image.bufferView, "images")
    size = Counter()
    for i, view in enumerate(doc.bufferViews):
        size[name.get(i, "other accessors")] += view.byteLength
    return size


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("files", nargs="+")
    for path in ap.parse_args().files:
        doc = gl.GLTF2().load(path)
        prims = [p for m in doc.meshes for p in m.primitives]
        V = sum(doc.accessors[p.attributes.POSITION].count for p in prims)
        T = sum(doc.accessors[p.indices].count for p in prims) // 3
        size = uses(doc)
        print(f"{path}: {V:,} vertices, {T:,} triangles, {len(prims)} primitives")
        for use, n in size.most_common():
            print(f"  {use:16s} {n / 1e6:8.2f} MB")
        print(f"  {'buffer':16s} {sum(size.values()) / 1e6:8.2f} MB, JSON {len(doc.to_json()) / 1e6:.2f} MB")


if __name__ == "__main__":
    main()
