// Liver-sized organ, written by meshes/make_liver.py: edit the script, not this file.
// The smooth shape comes as an STL (liver_shape.stl, written by the script); Gmsh re-meshes it.
General.NumThreads = 1;        // single-threaded meshing is reproducible
Mesh.RandomSeed = 1;
Mesh.RandomFactor = 1e-9;
Mesh.Algorithm = 6;            // Frontal-Delaunay surfaces
Mesh.Algorithm3D = 1;          // Delaunay volume
Mesh.Optimize = 1;
Mesh.MeshSizeFromCurvature = 16;
Mesh.MeshSizeMin = 0;
Mesh.MeshSizeMax = 0.014;
Mesh.ElementOrder = 1;
Merge "liver_shape.stl";
// One smooth surface: split into patches Gmsh can parametrize, then re-mesh them.
ClassifySurfaces{Pi / 4, 1, 1, Pi};
CreateGeometry;
Surface Loop(1) = Surface{:};
Volume(1) = {1};
// The fine box: this edge inside, the coarse size beyond the grading distance.
Field[1] = Box;
Field[1].VIn = 0.006;
Field[1].VOut = 0.014;
Field[1].XMin = -0.09; Field[1].XMax = 0.0;
Field[1].YMin = -0.025; Field[1].YMax = 0.025;
Field[1].ZMin = 0.0; Field[1].ZMax = 0.08;
Field[1].Thickness = 0.02;
Background Field = 1;
