// Colormaps (visopt/colormap.h): names round-trip, unknown names are Usage errors that list the
// valid ones, the ends match the published maps, t is clamped, the sequential maps have monotone
// luminance, and the render setting survives a session.
#include <cmath>

#include <gtest/gtest.h>

#include "visopt/colormap.h"
#include "visopt/error.h"
#include "visopt/session.h"

using namespace visopt;

namespace {

// sRGB decoding (IEC 61966-2-1), written out here rather than taken from the library.
float linear(float c) {
  return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}
glm::vec3 linear(glm::vec3 c) {
  return {linear(c.x), linear(c.y), linear(c.z)};
}

// Relative luminance of linear Rec. 709 / sRGB primaries.
float luminance(glm::vec3 c) {
  return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z;
}

void expectColour(glm::vec3 got, glm::vec3 want, const char* what) {
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], want[c], 1e-4f) << what << " channel " << c;
}

}  // namespace

TEST(Colormap, NamesRoundTrip) {
  const std::vector<std::string> names = colormapNames();
  ASSERT_EQ(names.size(), 5u);
  EXPECT_EQ(names.front(), "viridis");
  for (const std::string& name : names) EXPECT_EQ(toString(parseColormap(name)), name);
  EXPECT_EQ(parseColormap("Magma"), Colormap::Magma);
  EXPECT_EQ(parseColormap("COOLWARM"), Colormap::CoolWarm);
  EXPECT_EQ(parseColormap("gray"), Colormap::Grey);
}

TEST(Colormap, UnknownNameIsAUsageErrorListingTheValidOnes) {
  for (const char* bad : {"", "jet", "viridis ", "virdis"}) {
    try {
      parseColormap(bad);
      ADD_FAILURE() << "accepted \"" << bad << "\"";
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), ErrorKind::Usage);
      const std::string msg = e.what();
      EXPECT_NE(msg.find(std::string("\"") + bad + "\""), std::string::npos) << msg;
      for (const std::string& name : colormapNames())
        EXPECT_NE(msg.find(name), std::string::npos) << msg;
    }
  }
}

// The ends of matplotlib's viridis, magma and inferno (entries 0 and 255 of their 256-entry
// tables), Moreland's cool-warm (RGB 59,76,192 and 180,4,38) and black to white.
TEST(Colormap, EndColoursMatchThePublishedMaps) {
  expectColour(evaluateColormap(Colormap::Viridis, 0.f),
               linear(glm::vec3(0.267004f, 0.004874f, 0.329415f)), "viridis(0)");
  expectColour(evaluateColormap(Colormap::Viridis, 1.f),
               linear(glm::vec3(0.993248f, 0.906157f, 0.143936f)), "viridis(1)");
  expectColour(evaluateColormap(Colormap::Magma, 0.f),
               linear(glm::vec3(0.001462f, 0.000466f, 0.013866f)), "magma(0)");
  expectColour(evaluateColormap(Colormap::Magma, 1.f),
               linear(glm::vec3(0.987053f, 0.991438f, 0.749504f)), "magma(1)");
  expectColour(evaluateColormap(Colormap::Inferno, 0.f),
               linear(glm::vec3(0.001462f, 0.000466f, 0.013866f)), "inferno(0)");
  expectColour(evaluateColormap(Colormap::Inferno, 1.f),
               linear(glm::vec3(0.988362f, 0.998364f, 0.644924f)), "inferno(1)");
  expectColour(evaluateColormap(Colormap::CoolWarm, 0.f),
               linear(glm::vec3(59.f, 76.f, 192.f) / 255.f), "coolwarm(0)");
  expectColour(evaluateColormap(Colormap::CoolWarm, 1.f),
               linear(glm::vec3(180.f, 4.f, 38.f) / 255.f), "coolwarm(1)");
  expectColour(evaluateColormap(Colormap::Grey, 0.f), glm::vec3(0.f), "grey(0)");
  expectColour(evaluateColormap(Colormap::Grey, 1.f), glm::vec3(1.f), "grey(1)");
}

// Interior points of the published maps (viridis 0.5 is entry 128, magma 0.5 entry 128): the
// table is sampled from the real map, not an ad-hoc ramp.
TEST(Colormap, MidpointsMatchThePublishedMaps) {
  expectColour(evaluateColormap(Colormap::Viridis, 0.5f),
               linear(glm::vec3(0.127568f, 0.566949f, 0.550556f)), "viridis(0.5)");
  expectColour(evaluateColormap(Colormap::Magma, 0.5f),
               linear(glm::vec3(0.716387f, 0.214982f, 0.475290f)), "magma(0.5)");
  // Cool-warm is diverging: its middle is a neutral grey (221/255).
  const glm::vec3 mid = evaluateColormap(Colormap::CoolWarm, 0.5f);
  expectColour(mid, glm::vec3(linear(221.f / 255.f)), "coolwarm(0.5)");
}

TEST(Colormap, TIsClamped) {
  for (const std::string& name : colormapNames()) {
    const Colormap m = parseColormap(name);
    expectColour(evaluateColormap(m, -3.f), evaluateColormap(m, 0.f), name.c_str());
    expectColour(evaluateColormap(m, 7.f), evaluateColormap(m, 1.f), name.c_str());
    expectColour(evaluateColormap(m, std::nanf("")), evaluateColormap(m, 0.f), name.c_str());
  }
}

TEST(Colormap, SequentialMapsHaveMonotoneLuminance) {
  for (Colormap m : {Colormap::Viridis, Colormap::Magma, Colormap::Inferno, Colormap::Grey}) {
    float previous = -1.f;
    for (int i = 0; i <= 1000; ++i) {
      const glm::vec3 c = evaluateColormap(m, float(i) / 1000.f);
      for (int k = 0; k < 3; ++k) {
        EXPECT_GE(c[k], 0.f);
        EXPECT_LE(c[k], 1.f);
      }
      const float y = luminance(c);
      EXPECT_GT(y, previous) << toString(m) << " at t=" << float(i) / 1000.f;
      previous = y;
    }
  }
  // Cool-warm is not monotone: its luminance peaks in the middle.
  const float ends = std::max(luminance(evaluateColormap(Colormap::CoolWarm, 0.f)),
                              luminance(evaluateColormap(Colormap::CoolWarm, 1.f)));
  EXPECT_GT(luminance(evaluateColormap(Colormap::CoolWarm, 0.5f)), ends);
}

TEST(Colormap, SessionStoresTheDeviationColormapOnlyWhenNotDefault) {
  Session s;
  s.builtinScene = "shepp-logan";
  std::string json = sessionToJson(s);
  EXPECT_EQ(json.find("deviationColormap"), std::string::npos) << json;
  EXPECT_EQ(sessionFromJson(json, "a").render.deviationColormap, Colormap::Viridis);
  s.render.deviationColormap = Colormap::Inferno;
  json = sessionToJson(s);
  EXPECT_NE(json.find("\"deviationColormap\": \"inferno\""), std::string::npos) << json;
  EXPECT_EQ(sessionFromJson(json, "b").render.deviationColormap, Colormap::Inferno);
  // An unknown name is bad input naming the key.
  const std::string bad = json.replace(json.find("\"inferno\""), 9, "\"plasma\"");
  try {
    sessionFromJson(bad, "c.json");
    ADD_FAILURE() << "accepted an unknown colormap";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::BadInput);
    EXPECT_NE(std::string(e.what()).find("deviationColormap"), std::string::npos) << e.what();
  }
}
