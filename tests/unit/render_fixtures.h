// Small scenes built in code for renderer tests: homogeneous boxes with a known extinction.
#pragma once

#include "visopt/engine.h"
#include "visopt/transfer_function.h"
#include "visopt/volume.h"

namespace visopt::testing {

// A cube of n^3 voxels with unit spacing centred at the origin, all scalars 0.5.
inline Volume homogeneousCube(int n, Precision precision = Precision::FP32) {
  GridSpec g;
  g.dims = {n, n, n};
  g.origin = glm::vec3(-0.5f * float(n - 1));
  Volume v;
  v.name = "cube";
  v.sourcePath = "test:cube";
  v.scalarType = "float32";
  v.valueMin = 0.0;
  v.valueMax = 1.0;
  v.normalized = Field3D("volume", g, precision);
  v.normalized.fill(0.5f);
  return v;
}

// Constant extinction `mu` (per world unit) and constant albedo.
inline TransferFunction constantTransferFunction(float mu, glm::vec3 albedo) {
  TransferFunction tf;
  tf.name = "constant";
  tf.unitDistance = 1.f;
  const float alpha = 1.f - std::exp(-mu);
  tf.opacity = {{0.0, alpha}, {1.0, alpha}};
  tf.color = {{0.0, albedo}, {1.0, albedo}};
  return tf;
}

// Settings that isolate the single-scattering integral: no ambient, no background, pure HG.
inline RenderSettings pureSingleScattering(int size) {
  RenderSettings s;
  s.width = s.height = size;
  s.ambient = 0.f;
  s.background = glm::vec3(0.f);
  s.diffuse = s.specular = 0.f;
  s.hgAnisotropy = 0.f;
  s.earlyStop = 0.f;
  return s;
}

}  // namespace visopt::testing
