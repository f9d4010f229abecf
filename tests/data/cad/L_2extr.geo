// 1x1 square (lc 0.2) extruded up h=1 (5 layers), then side face x=1 extruded +x by 1.5 (6 layers) -> L
Mesh.Algorithm = 6;
Mesh.RecombinationAlgorithm = 1;
Mesh.ElementOrder = 1;
Mesh.CharacteristicLengthMin = 0.2;
Mesh.CharacteristicLengthMax = 0.2;
Point(1) = {0.000000, 0.000000, 0, 0.2};
Point(2) = {1.000000, 0.000000, 0, 0.2};
Point(3) = {1.000000, 1.000000, 0, 0.2};
Point(4) = {0.000000, 1.000000, 0, 0.2};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Curve Loop(1) = {1,2,3,4};
Plane Surface(1) = {1};
Recombine Surface{1};
out[] = Extrude {0,0,1.0} { Surface{1}; Layers{5}; Recombine; };
// out[2] is lateral face from line 1 (y=0); out[3] from line 2 (x=1)
o2[] = Extrude {1.5,0,0} { Surface{out[3]}; Layers{6}; Recombine; };
