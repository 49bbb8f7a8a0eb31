// When the workstation stops iterating while it follows the camera (follow_convergence.h): the
// energy quiet for five iterations in a row, a limit cycle without progress (the Cranium CT's
// recorded cycle), or the level's iteration budget; and not while the energy still falls.
#include <cmath>

#include <QTest>

#include "follow_convergence.h"

using namespace visopt;
using namespace visopt::ws;

namespace {

IterationStats stats(double energy, double meanDev = 0.0, double maxDev = 0.0) {
  IterationStats st;
  st.energyQ = energy;
  st.meanDeviationVoxels = meanDev;
  st.maxDeviationVoxels = maxDev;
  return st;
}

// The Cranium CT's coarsest level (README command), seven iterations of its cycle: energy, mean
// and largest deviation (voxels).
constexpr double kCtCycle[7][3] = {{-596904, 0.0412, 1.672}, {-598725, 0.0411, 1.638},
                                   {-598953, 0.0516, 1.660}, {-600564, 0.0491, 1.620},
                                   {-600497, 0.0357, 1.585}, {-597814, 0.0324, 1.646},
                                   {-595443, 0.0463, 1.660}};

// The follow iteration (1-based) at which following settles, or -1 within `iterations`.
template <class Energy>
int settlesAt(FollowConvergence& f, int iterations, Energy energy,
              const ExtinctionSettings& s = {}) {
  for (int i = 0; i < iterations; ++i)
    if (f.add(energy(i), s)) return i + 1;
  return -1;
}

}  // namespace

class FollowConvergenceTest : public QObject {
  Q_OBJECT
 private slots:
  void quietEnergySettlesAfterFiveIterations() {
    FollowConvergence f;
    // Falls by 1e-2 relative for three iterations, then stays put.
    const int at =
        settlesAt(f, 60, [](int i) { return stats(-1e5 * (1.0 + 0.01 * std::min(i, 3))); });
    QCOMPARE(at, 4 + FollowConvergence::kQuietIterations);
  }

  void aLimitCycleSettles() {
    FollowConvergence f;
    const int at = settlesAt(f, 60, [](int i) {
      const double* c = kCtCycle[i % 7];
      return stats(c[0], c[1], c[2]);
    });
    QCOMPARE(at, 16);  // two windows of eight: the quiet test alone never passes
  }

  void aFallingEnergyRunsToTheBudget() {
    FollowConvergence f;
    ExtinctionSettings s;
    s.maxIterationsPerLevel = 40;
    const int at = settlesAt(
        f, 60, [](int i) { return stats(-1e5 * (1.0 + 0.003 * i)); }, s);
    QCOMPARE(at, 40);
  }

  void resetStartsAgain() {
    FollowConvergence f;
    for (int i = 0; i < 15; ++i) {
      const double* c = kCtCycle[i % 7];
      QVERIFY(!f.add(stats(c[0], c[1], c[2]), {}));
    }
    f.reset();  // a new camera: the fifteen iterations before no longer count
    const int at = settlesAt(f, 60, [](int i) {
      const double* c = kCtCycle[i % 7];
      return stats(c[0], c[1], c[2]);
    });
    QCOMPARE(at, 16);
  }
};

QTEST_MAIN(FollowConvergenceTest)
#include "test_follow_convergence.moc"
