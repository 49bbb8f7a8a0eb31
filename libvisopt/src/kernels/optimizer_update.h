// Per-voxel optimiser updates: AdEMAMix (Pagliardini, Ablin, Grangier 2024; docs/methods.md §2) and
// Adam, on state stored as fp32 or fp16 fields.
//
// fp16 hazard: the second moment nu = EMA(g^2) underflows in fp16 (smallest subnormal ~6e-8)
// for gradients below ~2e-4, and an update m / (sqrt(nu) + eps) then explodes. The state
// therefore stores the root, rms = sqrt(nu), which keeps gradients down to ~1e-7 representable;
// the update is computed in fp32. Bias corrections and beta^t are computed in fp32 on the host.
#pragma once

#include <cmath>

#include "core/field_view.h"
#include "core/hd.h"

namespace visopt {

struct OptimizerCoefficients {
  bool ademamix = true;
  float lr = 1e-3f;
  float beta1 = 0.9f, beta2 = 0.999f, beta3 = 0.9999f;  // beta3 = beta3(t) this step
  float alpha = 0.f;                                    // alpha(t) this step
  float biasCorrection1 = 1.f;                          // 1 - beta1^t
  float biasCorrection2 = 1.f;                          // sqrt(1 - beta2^t)
  float epsilon = 1e-8f;
};

// The parameter change for gradient g at voxel v, updating the state: AdEMAMix when kAdemamix,
// Adam otherwise. Fields through any accessor with load/store (FieldView; the CPU rows' typed
// accessors of core/field_access.h): the one place the update is written.
template <bool kAdemamix, class A>
VISOPT_HD VISOPT_INLINE float optimizerStep(const A& m1, const A& m2, const A& rms, size_t v,
                                            float g, const OptimizerCoefficients& c) {
  const float m = c.beta1 * m1.load(v) + (1.f - c.beta1) * g;
  m1.store(v, m);
  const float r0 = rms.load(v);
  const float r = sqrtf(c.beta2 * r0 * r0 + (1.f - c.beta2) * g * g);
  rms.store(v, r);
  const float denom = r / c.biasCorrection2 + c.epsilon;
  float numer = m / c.biasCorrection1;
  if constexpr (kAdemamix) {
    const float slow = c.beta3 * m2.load(v) + (1.f - c.beta3) * g;  // not bias-corrected
    m2.store(v, slow);
    numer += c.alpha * slow;
  }
  return -c.lr * numer / denom;
}

struct OptimizerState {
  FieldView m1, m2, rms;  // m2 only for AdEMAMix

  // Returns the parameter change for gradient g at voxel v and updates the state.
  VISOPT_HD VISOPT_INLINE float step(size_t v, float g, const OptimizerCoefficients& c) const {
    return c.ademamix ? optimizerStep<true>(m1, m2, rms, v, g, c)
                      : optimizerStep<false>(m1, m2, rms, v, g, c);
  }
};

}  // namespace visopt
