"""The visual geometry of an artifact's bodies, per link, read from its URDFs with yourdfpy.

Our URDFs use boxes, cylinders, spheres and (rarely) meshes; each visual becomes one triangle mesh
in its *link* frame (the visual's origin applied), with its material's colour, so a viewer places
it by the link's recorded world pose alone (no forward kinematics, no simulation). Garments are
OBJ meshes whose vertices are the cloth's nodes: :func:`garment_faces` gives their triangles.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

DEFAULT_RGBA = (0.7, 0.7, 0.72, 1.0)


@dataclass
class VisualMesh:
    """One visual of a link: vertices (n, 3) m in the link frame, triangles (m, 3), colour RGBA in [0, 1]."""

    vertices: np.ndarray
    faces: np.ndarray
    rgba: tuple[float, float, float, float]


def _primitive(geometry, urdf_dir: Path):
    import trimesh

    if geometry.box is not None:
        return trimesh.creation.box(extents=geometry.box.size)
    if geometry.cylinder is not None:
        return trimesh.creation.cylinder(radius=geometry.cylinder.radius, height=geometry.cylinder.length, sections=24)
    if geometry.sphere is not None:
        return trimesh.creation.icosphere(subdivisions=2, radius=geometry.sphere.radius)
    if geometry.mesh is not None:
        mesh = trimesh.load(urdf_dir / geometry.mesh.filename, force="mesh", process=False)
        if geometry.mesh.scale is not None:
            mesh.apply_scale(geometry.mesh.scale)
        return mesh
    return None


def link_visuals(urdf_path: str | Path) -> dict[str, list[VisualMesh]]:
    """Link name → its visuals, for one URDF file."""
    import yourdfpy

    urdf_path = Path(urdf_path)
    model = yourdfpy.URDF.load(
        str(urdf_path), build_scene_graph=False, load_meshes=False, build_collision_scene_graph=False
    )
    named = {m.name: tuple(m.color.rgba) for m in model.robot.materials if m.color is not None}
    out: dict[str, list[VisualMesh]] = {}
    for link in model.robot.links:
        visuals = []
        for visual in link.visuals:
            mesh = _primitive(visual.geometry, urdf_path.parent)
            if mesh is None:
                continue
            if visual.origin is not None:
                mesh.apply_transform(visual.origin)
            material = visual.material
            rgba = DEFAULT_RGBA
            if material is not None:
                rgba = (
                    tuple(material.color.rgba) if material.color is not None else named.get(material.name, DEFAULT_RGBA)
                )
            visuals.append(
                VisualMesh(
                    np.asarray(mesh.vertices, dtype=np.float32),
                    np.asarray(mesh.faces, dtype=np.uint32),
                    tuple(float(x) for x in rgba),
                )
            )
        out[link.name] = visuals
    return out


def garment_faces(obj_path: str | Path) -> np.ndarray:
    """(m, 3) triangles of a garment's OBJ, indexing its nodes in file order."""
    import trimesh

    mesh = trimesh.load(Path(obj_path), force="mesh", process=False)
    return np.asarray(mesh.faces, dtype=np.uint32)
