// Spatial table frame: four 0.75 m legs under a 1.2 m x 0.8 m top frame, feet clamped.
// Made with gmsh 4.8:   gmsh -1 -format msh41 table.geo -o table.msh
h = 0.1;
H = 0.75; Lx = 1.2; Ly = 0.8;
Point(1) = {0, 0, 0, h};   Point(2) = {Lx, 0, 0, h};
Point(3) = {Lx, Ly, 0, h}; Point(4) = {0, Ly, 0, h};
Point(5) = {0, 0, H, h};   Point(6) = {Lx, 0, H, h};
Point(7) = {Lx, Ly, H, h}; Point(8) = {0, Ly, H, h};
Line(1) = {1, 5}; Line(2) = {2, 6}; Line(3) = {3, 7}; Line(4) = {4, 8};
Line(5) = {5, 6}; Line(6) = {6, 7}; Line(7) = {7, 8}; Line(8) = {8, 5};
Physical Line("legs") = {1, 2, 3, 4};
Physical Line("top") = {5, 6, 7, 8};
Physical Point("feet") = {1, 2, 3, 4};
Physical Point("corner") = {7};
Mesh.ElementOrder = 1;
