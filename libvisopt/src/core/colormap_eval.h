// Colormap evaluation callable from both backends (see visopt/colormap.h). Each map is a table
// of sRGB control points sampled uniformly from the published map (matplotlib's viridis, magma
// and inferno at every 16th of their 256 entries, Moreland's cool-warm at nine points, and a
// grey ramp); both neighbours are decoded to linear light and interpolated there, so the
// luminance between two control points is monotone whenever it is at the points.
#pragma once

#include <cmath>

#include <glm/glm.hpp>

#include "core/hd.h"
#include "visopt/colormap.h"

namespace visopt {

// The sRGB electro-optical transfer function (IEC 61966-2-1).
VISOPT_HD inline float srgbToLinear(float c) {
  return c <= 0.04045f ? c / 12.92f : powf((c + 0.055f) / 1.055f, 2.4f);
}

VISOPT_HD inline int colormapPointCount(Colormap map) {
  switch (map) {
    case Colormap::CoolWarm:
      return 9;
    case Colormap::Grey:
      return 2;
    default:
      return 17;
  }
}

// Control point i (0 <= i < colormapPointCount(map)) of `map`, in sRGB.
VISOPT_HD inline glm::vec3 colormapControlPoint(Colormap map, int i) {
  switch (map) {
    case Colormap::Magma: {
      const float m[17][3] = {{0.001462f, 0.000466f, 0.013866f}, {0.039608f, 0.031090f, 0.133515f},
                              {0.113094f, 0.065492f, 0.276784f}, {0.211718f, 0.061992f, 0.418647f},
                              {0.316654f, 0.071690f, 0.485380f}, {0.414709f, 0.110431f, 0.504662f},
                              {0.512831f, 0.148179f, 0.507648f}, {0.613617f, 0.181811f, 0.498536f},
                              {0.716387f, 0.214982f, 0.475290f}, {0.816914f, 0.255895f, 0.436461f},
                              {0.904281f, 0.319610f, 0.388137f}, {0.960949f, 0.418323f, 0.359630f},
                              {0.986700f, 0.535582f, 0.382210f}, {0.996096f, 0.653659f, 0.446213f},
                              {0.996898f, 0.769591f, 0.534892f}, {0.992440f, 0.884330f, 0.640099f},
                              {0.987053f, 0.991438f, 0.749504f}};
      return glm::vec3(m[i][0], m[i][1], m[i][2]);
    }
    case Colormap::Inferno: {
      const float m[17][3] = {{0.001462f, 0.000466f, 0.013866f}, {0.042253f, 0.028139f, 0.141141f},
                              {0.129285f, 0.047293f, 0.290788f}, {0.238273f, 0.036621f, 0.396353f},
                              {0.341500f, 0.062325f, 0.429425f}, {0.441207f, 0.099338f, 0.431594f},
                              {0.540920f, 0.134729f, 0.415123f}, {0.640135f, 0.171438f, 0.381065f},
                              {0.735683f, 0.215906f, 0.330245f}, {0.822386f, 0.275197f, 0.266085f},
                              {0.894305f, 0.353399f, 0.193584f}, {0.946965f, 0.449191f, 0.115272f},
                              {0.978422f, 0.557937f, 0.034931f}, {0.987874f, 0.675267f, 0.065257f},
                              {0.974638f, 0.797692f, 0.206332f}, {0.947594f, 0.917399f, 0.410665f},
                              {0.988362f, 0.998364f, 0.644924f}};
      return glm::vec3(m[i][0], m[i][1], m[i][2]);
    }
    case Colormap::CoolWarm: {
      // Moreland, "Diverging Color Maps for Scientific Visualization" (2009), 8-bit values.
      const float m[9][3] = {{59.f, 76.f, 192.f},   {98.f, 130.f, 234.f},  {141.f, 176.f, 254.f},
                             {184.f, 208.f, 249.f}, {221.f, 221.f, 221.f}, {245.f, 196.f, 173.f},
                             {244.f, 154.f, 123.f}, {222.f, 96.f, 77.f},   {180.f, 4.f, 38.f}};
      return glm::vec3(m[i][0], m[i][1], m[i][2]) / 255.f;
    }
    case Colormap::Grey:
      return glm::vec3(float(i));
    case Colormap::Viridis:
    default: {
      const float m[17][3] = {{0.267004f, 0.004874f, 0.329415f}, {0.282327f, 0.094955f, 0.417331f},
                              {0.278826f, 0.175490f, 0.483397f}, {0.258965f, 0.251537f, 0.524736f},
                              {0.229739f, 0.322361f, 0.545706f}, {0.199430f, 0.387607f, 0.554642f},
                              {0.172719f, 0.448791f, 0.557885f}, {0.149039f, 0.508051f, 0.557250f},
                              {0.127568f, 0.566949f, 0.550556f}, {0.120638f, 0.625828f, 0.533488f},
                              {0.157851f, 0.683765f, 0.501686f}, {0.246070f, 0.738910f, 0.452024f},
                              {0.369214f, 0.788888f, 0.382914f}, {0.515992f, 0.831158f, 0.294279f},
                              {0.678489f, 0.863742f, 0.189503f}, {0.845561f, 0.887322f, 0.099702f},
                              {0.993248f, 0.906157f, 0.143936f}};
      return glm::vec3(m[i][0], m[i][1], m[i][2]);
    }
  }
}

// The colour of `map` at t (clamped to [0, 1]; NaN reads as 0), in linear RGB.
VISOPT_HD inline glm::vec3 colormapColor(Colormap map, float t) {
  const int count = colormapPointCount(map);
  t = t > 0.f ? (t < 1.f ? t : 1.f) : 0.f;
  const float x = t * float(count - 1);
  const int i = x >= float(count - 1) ? count - 2 : int(x);
  const float f = x - float(i);
  const glm::vec3 a = colormapControlPoint(map, i);
  const glm::vec3 b = colormapControlPoint(map, i + 1);
  const glm::vec3 la(srgbToLinear(a.x), srgbToLinear(a.y), srgbToLinear(a.z));
  const glm::vec3 lb(srgbToLinear(b.x), srgbToLinear(b.y), srgbToLinear(b.z));
  return la + f * (lb - la);
}

}  // namespace visopt
