// The frog render surface (meshes/make_frog.py): frog.geo meshed in 2D, finer.
Include "frog.geo";
Mesh.MeshSizeMax = 0.0013;
