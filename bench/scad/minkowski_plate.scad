minkowski() {
  difference() { cube([30,20,4]); for (x=[7,15,23]) translate([x,10,-1]) cylinder(r=3, h=6, $fn=24); }
  cylinder(r=2, h=1, $fn=16);
}
