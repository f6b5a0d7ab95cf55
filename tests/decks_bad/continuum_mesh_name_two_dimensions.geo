// A surface and its right side both named "a" (Physical Surface and Physical Curve), with
// a crack line, the left side and a corner point (mesh of continuum_mesh_name_two_dimensions.dat):
// gmsh -2 -format msh41 continuum_mesh_name_two_dimensions.geo
lc=0.25;
Point(1)={0,0,0,lc}; Point(2)={2,0,0,lc}; Point(3)={2,1,0,lc}; Point(4)={0,1,0,lc};
Point(5)={1,0.2,0,lc}; Point(6)={1,0.8,0,lc};
Line(1)={1,2}; Line(2)={2,3}; Line(3)={3,4}; Line(4)={4,1}; Line(5)={5,6};
Curve Loop(1)={1,2,3,4}; Plane Surface(1)={1}; Line{5} In Surface{1};
Physical Surface("a")={1};
Physical Curve("a")={2};
Physical Curve("left side")={4};
Physical Curve("crack")={5};
Physical Point("o")={1};
