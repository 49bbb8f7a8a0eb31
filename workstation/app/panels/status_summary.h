// The status bar's text: the optimisation's progress, frame rate, memory and state.
#pragma once

#include <cstddef>

#include <QString>

#include <visopt/optimization.h>

namespace visopt::ws {

// "level 2 · it 35 · E −1.05e6 · V 0.64 · 12.3 fps · 410 MB · running".
//  - level and iteration as the library counts them, E = stats->energy() with three significant
//    digits (scientific outside [0.01, 10000), exponent without '+' or padding, U+2212 minus),
//    V = stats->visibilityView with two decimals; all four are left out when `stats` is null.
//  - fps with one decimal, left out when fps <= 0.
//  - memory in decimal units: whole MB below 1 GB, else GB with two decimals.
//  - the state: "frozen" when frozen, else "running" or "paused".
QString formatStatus(const visopt::IterationStats* stats, double fps, size_t bytes, bool frozen,
                     bool running);

// A number with three significant digits as formatStatus writes it ("−1.05e6", "0.64", "0").
QString formatSignificant(double value);

// Bytes in decimal units: "410 MB", "1.23 GB", "0 MB".
QString formatBytes(size_t bytes);

}  // namespace visopt::ws
