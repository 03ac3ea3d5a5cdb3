minkowski() {
  linear_extrude(5) polygon([[0,0],[20,0],[20,5],[5,5],[5,15],[0,15]]);
  sphere(1, $fn=16);
}
