// Two elastic blocks for input/interface_shear.dat: a steel-like bottom block [0, 0.5] x [0, 0.2]
// and an aluminium-like top block [0, 0.5] x [0.25, 0.45] (metres), 0.05 m apart; the disk
// layer between them overlaps each block in a band one element (0.025 m) deep.
// Mesh with: gmsh -2 -format msh41 interface_shear.geo -o interface_shear.msh
// Physical groups (named sets of the deck): surfaces bottom_block, top_block; curves base
// (y = 0) and top (y = 0.45).
w = 0.5;
Point(1) = {0, 0, 0};
Point(2) = {w, 0, 0};
Point(3) = {w, 0.2, 0};
Point(4) = {0, 0.2, 0};
Point(5) = {0, 0.25, 0};
Point(6) = {w, 0.25, 0};
Point(7) = {w, 0.45, 0};
Point(8) = {0, 0.45, 0};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Line(5) = {5, 6};
Line(6) = {6, 7};
Line(7) = {7, 8};
Line(8) = {8, 5};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Curve Loop(2) = {5, 6, 7, 8};
Plane Surface(2) = {2};
// 20 x 8 square quadrangles of 0.025 m per block: mesh lines on the bands' edges.
Transfinite Curve{1, 3, 5, 7} = 21;
Transfinite Curve{2, 4, 6, 8} = 9;
Transfinite Surface{1, 2};
Recombine Surface{1, 2};
Physical Surface("bottom_block") = {1};
Physical Surface("top_block") = {2};
Physical Curve("base") = {1};
Physical Curve("top") = {7};
