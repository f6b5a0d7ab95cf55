// Two unit squares, 2 x 2 quadrangles each, joined at a single corner node (1, 1): a hinge
// (mesh of continuum_hinge.dat): gmsh -2 -format msh41 continuum_hinge.geo
Point(1) = {0, 0, 0}; Point(2) = {1, 0, 0}; Point(3) = {1, 1, 0}; Point(4) = {0, 1, 0};
Point(6) = {2, 1, 0}; Point(7) = {2, 2, 0}; Point(8) = {1, 2, 0};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Line(5) = {3, 6}; Line(6) = {6, 7}; Line(7) = {7, 8}; Line(8) = {8, 3};
Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};
Curve Loop(2) = {5, 6, 7, 8}; Plane Surface(2) = {2};
Transfinite Curve{1:8} = 3; Transfinite Surface{1, 2}; Recombine Surface{1, 2};
Physical Surface("blocks") = {1, 2};
Physical Curve("base") = {1};
Physical Curve("top") = {7};
