// The (key, member) tables of the settings structs a session stores (see json_fields.h). A
// member missing here is not saved: add new settings here, with a key that never changes.
#pragma once

#include "session/json_fields.h"
#include "visopt/clearview.h"
#include "visopt/engine.h"
#include "visopt/level_set.h"
#include "visopt/optimization.h"
#include "visopt/render_settings.h"

namespace visopt::session {

const FieldTable<ExtinctionSettings>& extinctionFields();
const FieldTable<LevelSetSettings>& levelSetFields();
const FieldTable<ImportanceLens>& lensFields();
const FieldTable<RenderSettings>& renderFields();
const FieldTable<ContextSurfaceSpec>& surfaceFields();  // all but "source"
const FieldTable<Camera>& cameraFields();
const FieldTable<PointLight>& lightFields();
// The plain members of ClearViewSettings a session stores: not the layers, measure and shaders
// (session_json.cpp writes those by name), nor width, height and focusPixel (the view's).
const FieldTable<ClearViewSettings>& clearViewFields();

}  // namespace visopt::session
