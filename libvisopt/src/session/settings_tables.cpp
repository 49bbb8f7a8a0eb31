#include "session/settings_tables.h"

namespace visopt::session {

const FieldTable<ExtinctionSettings>& extinctionFields() {
  using S = ExtinctionSettings;
  static const auto table = FieldTable<S>()
                                .add("rho", &S::rho)
                                .add("q", &S::q)
                                .add("r", &S::r)
                                .add("muMax", &S::muMax)
                                .add("learningRate", &S::learningRate)
                                .add("beta1", &S::beta1)
                                .add("beta2", &S::beta2)
                                .add("beta3", &S::beta3)
                                .add("alpha", &S::alpha)
                                .add("epsilon", &S::epsilon)
                                .add("alphaWarmup", &S::alphaWarmup)
                                .add("beta3Warmup", &S::beta3Warmup)
                                .add("levels", &S::levels)
                                .add("maxIterationsPerLevel", &S::maxIterationsPerLevel)
                                .add("tolerance", &S::tolerance)
                                .add("minIterationsPerLevel", &S::minIterationsPerLevel)
                                .add("frustumScale", &S::frustumScale)
                                .add("depthCells", &S::depthCells)
                                .add("lightGridSize", &S::lightGridSize);
  return table;
}

const FieldTable<LevelSetSettings>& levelSetFields() {
  using S = LevelSetSettings;
  static const auto table = FieldTable<S>()
                                .add("lambda", &S::lambda)
                                .add("curvatureEpsilon", &S::curvatureEpsilon)
                                .add("cfl", &S::cfl)
                                .add("substeps", &S::substeps)
                                .add("reach", &S::reach)
                                .add("redistanceIterations", &S::redistanceIterations)
                                .add("redistanceTolerance", &S::redistanceTolerance)
                                .add("spatialOrder", &S::spatialOrder)
                                .add("band", &S::band)
                                .add("semiImplicit", &S::semiImplicit);
  return table;
}

const FieldTable<ImportanceLens>& lensFields() {
  using S = ImportanceLens;
  static const auto table = FieldTable<S>()
                                .add("x", &S::x)
                                .add("y", &S::y)
                                .add("radius", &S::radius)
                                .add("strength", &S::strength);
  return table;
}

const FieldTable<RenderSettings>& renderFields() {
  using S = RenderSettings;
  static const auto table = FieldTable<S>()
                                .add("width", &S::width)
                                .add("height", &S::height)
                                .add("stepFactor", &S::stepFactor)
                                .add("jitter", &S::jitter)
                                .add("seed", &S::seed)
                                .add("preview", &S::preview)
                                .add("previewFactor", &S::previewFactor)
                                .add("hgAnisotropy", &S::hgAnisotropy)
                                .add("diffuse", &S::diffuse)
                                .add("specular", &S::specular)
                                .add("shininess", &S::shininess)
                                .add("surfaceGradient", &S::surfaceGradient)
                                .add("ambient", &S::ambient)
                                .add("background", &S::background)
                                .add("exposure", &S::exposure)
                                .add("lightGridSize", &S::lightGridSize)
                                .add("lightGridDepth", &S::lightGridDepth)
                                .add("earlyStop", &S::earlyStop)
                                .add("surfaceSpecular", &S::surfaceSpecular)
                                .add("surfaceShininess", &S::surfaceShininess)
                                .add("ambientOcclusion", &S::ambientOcclusion)
                                .add("ambientOcclusionRadius", &S::ambientOcclusionRadius)
                                .add("deviationView", &S::deviationView)
                                .add("deviationMaxVoxels", &S::deviationMaxVoxels)
                                .add("importanceOverlay", &S::importanceOverlay)
                                .add("worldMaskOverlay", &S::worldMaskOverlay);
  return table;
}

const FieldTable<ContextSurfaceSpec>& surfaceFields() {
  using S = ContextSurfaceSpec;
  static const auto table = FieldTable<S>()
                                .add("filled", &S::filled)
                                .add("shell", &S::shell)
                                .add("color", &S::color)
                                .add("visible", &S::visible);
  return table;
}

const FieldTable<Camera>& cameraFields() {
  using S = Camera;
  static const auto table = FieldTable<S>()
                                .add("eye", &S::eye)
                                .add("target", &S::target)
                                .add("up", &S::up)
                                .add("fovY", &S::fovYDegrees);
  return table;
}

const FieldTable<PointLight>& lightFields() {
  using S = PointLight;
  static const auto table = FieldTable<S>()
                                .add("position", &S::position)
                                .add("intensity", &S::intensity)
                                .add("color", &S::color);
  return table;
}

const FieldTable<ClearViewSettings>& clearViewFields() {
  using S = ClearViewSettings;
  static const auto table = FieldTable<S>()
                                .add("volumeLayer", &S::volumeLayer)
                                .add("size", &S::size)
                                .add("weight", &S::weight)
                                .add("distanceScale", &S::distanceScale)
                                .add("border", &S::border)
                                .add("ambient", &S::ambient)
                                .add("headlight", &S::headlight)
                                .add("contextColor", &S::contextColor)
                                .add("focusColor", &S::focusColor)
                                .add("background", &S::background);
  return table;
}

}  // namespace visopt::session
