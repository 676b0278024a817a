"""gmsh meshes of the layered beam for the 2D plane-stress reference, debonds drawn as cracks.

gmsh is imported here (in this package) and nowhere else in the project.
"""

from sandwich.meshes.build import build_mesh
from sandwich.meshes.layered_mesh import LayeredMesh
from sandwich.meshes.quality import MeshQuality, quality_report
from sandwich.meshes.write import write_mesh

__all__ = ["LayeredMesh", "MeshQuality", "build_mesh", "quality_report", "write_mesh"]
