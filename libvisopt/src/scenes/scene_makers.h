// One maker per built-in scene; scene_registry.cpp maps names to them.
#pragma once

#include "visopt/scenes.h"

namespace visopt::scenes {

BuiltinScene makeSheppLogan(int resolution, Precision precision, MemoryLedger* ledger);
BuiltinScene makeMarschnerLobb(int resolution, Precision precision, MemoryLedger* ledger);
BuiltinScene makeEarthMantle(int resolution, Precision precision, MemoryLedger* ledger);
BuiltinScene makeMixer(int resolution, Precision precision, MemoryLedger* ledger);
BuiltinScene makeHydrogen(int resolution, Precision precision, MemoryLedger* ledger);
BuiltinScene makeCtHead(int resolution, Precision precision, MemoryLedger* ledger);
BuiltinScene makeWallAndMembrane(int resolution, Precision precision, MemoryLedger* ledger);
BuiltinScene makeLevelSetCases(int resolution, Precision precision, MemoryLedger* ledger);

}  // namespace visopt::scenes
