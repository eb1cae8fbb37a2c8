// Frog specimen, written by meshes/make_frog.py: edit the script, not this file.
// Body and head are ellipsoids, the legs cylinders; one OpenCASCADE union.
SetFactory("OpenCASCADE");
General.NumThreads = 1;        // single-threaded meshing is reproducible
Mesh.RandomSeed = 1;
Mesh.RandomFactor = 1e-9;
Mesh.Algorithm = 6;            // Frontal-Delaunay surfaces
Mesh.Algorithm3D = 1;          // Delaunay volume
Mesh.Optimize = 1;
Mesh.MeshSizeFromCurvature = 0;
Mesh.MeshSizeExtendFromBoundary = 1;
Mesh.MeshSizeMin = 0;
Mesh.MeshSizeMax = 0.007;
Mesh.ElementOrder = 1;

Sphere(1) = {0, 0, 0, 1};
Dilate {{0, 0, 0}, {0.035, 0.024, 0.016}} { Volume{1}; }
Translate {0, 0, 0.02} { Volume{1}; }
Sphere(2) = {0, 0, 0, 1};
Dilate {{0, 0, 0}, {0.02, 0.02, 0.012}} { Volume{2}; }
Translate {0.036, 0, 0.024} { Volume{2}; }
Cylinder(3) = {0.016, 0.008, 0.016, 0.018, 0.022, -0.018, 0.0045};
Cylinder(4) = {0.016, -0.008, 0.016, 0.018, -0.022, -0.018, 0.0045};
Cylinder(5) = {-0.018, 0.008, 0.018, -0.022, 0.032, -0.01, 0.0055};
Cylinder(6) = {-0.018, -0.008, 0.018, -0.022, -0.032, -0.01, 0.0055};
Cylinder(7) = {-0.04, 0.04, 0.008, -0.028, -0.012, -0.004, 0.0045};
Cylinder(8) = {-0.04, -0.04, 0.008, -0.028, 0.012, -0.004, 0.0045};
Sphere(9) = {-0.04, 0.04, 0.008, 0.0055};
Sphere(10) = {-0.04, -0.04, 0.008, 0.0055};
BooleanUnion{ Volume{1}; Delete; }{ Volume{2:10}; Delete; }
