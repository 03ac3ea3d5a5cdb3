minkowski() { rotate_extrude($fn=48) translate([10,0]) square(2); sphere(0.5, $fn=12); }
