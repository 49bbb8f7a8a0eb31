// The P-square algorithm (Jain & Chlamtac 1985): an online estimate of the p-quantile of a
// sequence with five markers and no storage of the values, as Rapp et al. 2022 §4.1 use it for
// the per-pixel error along a ray. Exact while at most five values have been seen.
#pragma once

#include "core/hd.h"

namespace visopt {

struct PSquare {
  float p = 0.5f;
  int count = 0;
  float q[5] = {};     // marker heights
  float n[5] = {};     // marker positions (1-based)
  float want[5] = {};  // desired positions
  float wantStep[5] = {};

  VISOPT_HD explicit PSquare(float quantile) : p(quantile) {
    want[0] = 1.f;
    want[1] = 1.f + 2.f * p;
    want[2] = 1.f + 4.f * p;
    want[3] = 3.f + 2.f * p;
    want[4] = 5.f;
    wantStep[0] = 0.f;
    wantStep[1] = p / 2.f;
    wantStep[2] = p;
    wantStep[3] = (1.f + p) / 2.f;
    wantStep[4] = 1.f;
  }

  VISOPT_HD void add(float x) {
    if (count < 5) {
      // Insertion into the sorted first five.
      int i = count++;
      while (i > 0 && q[i - 1] > x) {
        q[i] = q[i - 1];
        --i;
      }
      q[i] = x;
      if (count == 5)
        for (int k = 0; k < 5; ++k) n[k] = float(k + 1);
      return;
    }
    ++count;
    int k;  // the cell q[k] <= x < q[k + 1]
    if (x < q[0]) {
      q[0] = x;
      k = 0;
    } else if (x >= q[4]) {
      q[4] = x;
      k = 3;
    } else {
      k = 0;
      while (k < 3 && x >= q[k + 1]) ++k;
    }
    for (int i = k + 1; i < 5; ++i) n[i] += 1.f;
    for (int i = 0; i < 5; ++i) want[i] += wantStep[i];
    for (int i = 1; i < 4; ++i) {
      const float d = want[i] - n[i];
      if ((d >= 1.f && n[i + 1] - n[i] > 1.f) || (d <= -1.f && n[i - 1] - n[i] < -1.f)) {
        const float s = d >= 0.f ? 1.f : -1.f;
        // Piecewise-parabolic prediction, linear where it would leave the neighbours.
        const float qp = q[i] + s / (n[i + 1] - n[i - 1]) *
                                    ((n[i] - n[i - 1] + s) * (q[i + 1] - q[i]) / (n[i + 1] - n[i]) +
                                     (n[i + 1] - n[i] - s) * (q[i] - q[i - 1]) / (n[i] - n[i - 1]));
        if (q[i - 1] < qp && qp < q[i + 1]) {
          q[i] = qp;
        } else {
          const int j = s > 0.f ? i + 1 : i - 1;
          q[i] = q[i] + s * (q[j] - q[i]) / (n[j] - n[i]);
        }
        n[i] += s;
      }
    }
  }

  // The estimate (0 before any value; the exact order statistic of up to five values).
  VISOPT_HD float value() const {
    if (count == 0) return 0.f;
    if (count <= 5) {
      int i = int(p * float(count - 1) + 0.5f);
      return q[i < count ? i : count - 1];
    }
    return q[2];
  }
};

}  // namespace visopt
