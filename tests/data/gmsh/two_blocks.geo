// Two blocks side by side for the Gmsh reader tests: [0, 1] x [0, 1] in triangles and
// [1, 2] x [0, 1] in quadrangles (recombined), sharing the edge x = 1.
// The test suite meshes it with: gmsh -2 -format msh41 two_blocks.geo -o two_blocks.msh
h = 0.25;
Point(1) = {0, 0, 0, h};
Point(2) = {1, 0, 0, h};
Point(3) = {2, 0, 0, h};
Point(4) = {2, 1, 0, h};
Point(5) = {1, 1, 0, h};
Point(6) = {0, 1, 0, h};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 5};
Line(5) = {5, 6};
Line(6) = {6, 1};
Line(7) = {2, 5};
Curve Loop(1) = {1, 7, 5, 6};
Plane Surface(1) = {1};
// The right block's loop runs clockwise: its elements come out clockwise and the reader
// must turn them.
Curve Loop(2) = {-2, 7, -4, -3};
Plane Surface(2) = {2};
Transfinite Curve{2, 3, 4, 7} = 5;
Transfinite Surface{2};
Recombine Surface{2};
Physical Surface("triangles") = {1};
Physical Surface("quads") = {2};
Physical Surface("all") = {1, 2};
Physical Curve("clamped") = {6};
Physical Curve("loaded") = {3};
Physical Curve("bottom") = {1, 2};
// A group without a name: the reader calls it physical_1_20.
Physical Curve(20) = {4, 5};
Physical Point("origin") = {1};
