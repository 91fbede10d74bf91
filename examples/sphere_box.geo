// Sphere in a box: a unit sphere inside a box of side 4, both volumes kept (the sphere's
// surface is an internal face). Regenerate the STEP with
//   gmsh examples/sphere_box.geo -0 -o examples/sphere_box.step
SetFactory("OpenCASCADE");
Box(1) = {-2, -2, -2, 4, 4, 4};
Sphere(2) = {0, 0, 0, 1};
BooleanFragments{ Volume{1}; Delete; }{ Volume{2}; Delete; }
