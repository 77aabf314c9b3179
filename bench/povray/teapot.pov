#version 3.7;
// testdata/teapot.ron for POV-Ray 3.7: the Utah teapot, Whitted shading (ambient 0.1,
// Lambert, Phong highlight, mirror reflection 0.3), one point light, shadows.
#include "common.inc"
background { rgb <0.05, 0.05, 0.08> }
union {
  #include "teapot.inc"
  pigment { rgb <0.9, 0.5, 0.6> }
  finish { ambient 0.1 diffuse 1 phong 0.6 phong_size 40 reflection 0.3 }
}
