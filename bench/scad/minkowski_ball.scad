minkowski() {
  difference() { sphere(10); translate([5,5,5]) cube(10, center=true); }
  sphere(1, $fn=8);
}
