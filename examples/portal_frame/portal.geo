// Planar portal frame: two 3 m columns, a 4 m beam, feet clamped. Made with gmsh 4.8:
//   gmsh -1 -format msh22 portal.geo -o portal.msh
h = 0.25;                       // element length, m
Point(1) = {0, 0, 0, h};
Point(2) = {0, 3, 0, h};
Point(3) = {4, 3, 0, h};
Point(4) = {4, 0, 0, h};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Physical Line("columns") = {1, 3};
Physical Line("beam") = {2};
Physical Point("base") = {1, 4};
Physical Point("corner") = {2};
Mesh.ElementOrder = 1;
