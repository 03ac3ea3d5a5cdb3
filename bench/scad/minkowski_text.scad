minkowski() {
  linear_extrude(2) text("PIC", size=10);
  sphere(0.5, $fn=12);
}
