minkowski() { difference() { cube([20,20,10]); translate([2,2,2]) cube([16,16,10]); } sphere(1, $fn=16); }
