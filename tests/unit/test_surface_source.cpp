// SurfaceSource (visopt/context_surface.h), the one parser and formatter of a context surface's
// source text: each form parses to what it says and formats back to the canonical text, values
// survive the round trip exactly, a file may hold colons, and malformed text is refused naming
// it.
#include <string>

#include <gtest/gtest.h>

#include "visopt/context_surface.h"
#include "visopt/error.h"

using namespace visopt;

TEST(SurfaceSource, EachFormParsesToWhatItSays) {
  SurfaceSource s = SurfaceSource::parse("iso:-400");
  EXPECT_EQ(s.kind, SurfaceSource::Kind::Iso);
  EXPECT_EQ(s.isoValue, -400.0);
  EXPECT_TRUE(s.insideHigh);
  EXPECT_EQ(s.format(), "iso:-400:inside-high");

  s = SurfaceSource::parse("iso:0.35:inside-low");
  EXPECT_EQ(s.isoValue, 0.35);
  EXPECT_FALSE(s.insideHigh);
  EXPECT_EQ(s.format(), "iso:0.35:inside-low");

  s = SurfaceSource::parse("mesh:/data/a:b/bunny.obj");
  EXPECT_EQ(s.kind, SurfaceSource::Kind::Mesh);
  EXPECT_EQ(s.file, "/data/a:b/bunny.obj");
  EXPECT_EQ(s.format(), "mesh:/data/a:b/bunny.obj");

  s = SurfaceSource::parse("vdb:skin.vdb");
  EXPECT_EQ(s.kind, SurfaceSource::Kind::Vdb);
  EXPECT_EQ(s.file, "skin.vdb");
  EXPECT_TRUE(s.hasFile());
  EXPECT_FALSE(SurfaceSource::iso(1.0).hasFile());
}

TEST(SurfaceSource, ValuesSurviveTheRoundTripExactly) {
  for (double v : {0.1, -400.0, 1e-7, 123456.789, 2.0 / 3.0, -0.0, 5e300})
    for (bool high : {true, false}) {
      const SurfaceSource a = SurfaceSource::iso(v, high);
      const SurfaceSource b = SurfaceSource::parse(a.format());
      EXPECT_EQ(b.isoValue, v) << a.format();
      EXPECT_EQ(b.insideHigh, high);
      EXPECT_EQ(a, b);
    }
  EXPECT_EQ(SurfaceSource::iso(0.1).format(), "iso:0.1:inside-high");  // shortest form
}

TEST(SurfaceSource, MalformedTextIsRefusedNamingIt) {
  for (const char* bad : {"iso:abc", "iso:1:sideways", "iso:", "iso:nan", "iso:inf", "iso:1.5x",
                          "mesh:", "vdb:", "sphere:3", "", "ISO:1"}) {
    try {
      SurfaceSource::parse(bad);
      ADD_FAILURE() << "'" << bad << "' was accepted";
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), ErrorKind::Usage) << bad;
      EXPECT_NE(std::string(e.what()).find(std::string("'") + bad + "'"), std::string::npos)
          << e.what();
    }
  }
}
