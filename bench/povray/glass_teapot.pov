#version 3.7;
// testdata/glass_teapot.ron for POV-Ray 3.7: the teapot in glass (transmit 0.9, ior 1.5,
// Fresnel reflection, Phong highlight 0.8 / 80, no diffuse), max trace level 5.
#include "common.inc"
background { rgb <0.25, 0.3, 0.4> }
union {
  #include "teapot.inc"
  pigment { rgbt <0, 0, 0, 0.9> }
  finish { ambient 0 diffuse 0 phong 0.8 phong_size 80 reflection { 0, 1 fresnel on } conserve_energy }
  interior { ior 1.5 }
}
