// World-mask painting (Himmler & Günther 2026, §III-F, R5): the sphere brush marks exactly the
// voxels whose centres lie within its world radius of the stroke (anisotropic spacing and a rotated
// grid), strokes undo and redo bitwise, Escape leaves no trace, the history's memory cap drops the
// oldest entries, the value range limits the change, and picking finds a sphere SDF where the
// analytic ray-sphere intersection is.
#include <cmath>
#include <memory>
#include <numbers>
#include <optional>
#include <vector>

#include <QKeyEvent>
#include <QMouseEvent>
#include <QSignalSpy>
#include <QTest>
#include <QWidget>

#include <glm/gtc/matrix_transform.hpp>

#include "tools/mask_editor.h"
#include "tools/mask_paint_tool.h"
#include "tools/picking.h"

using namespace visopt;
using namespace visopt::ws;

namespace {

// A widget that hands its events to a tool, as the viewport does.
class ToolHost : public QWidget {
 public:
  ToolHost(ViewportTool* tool, ViewContext view) : tool_(tool), view_(std::move(view)) {
    resize(view_.imageSize);
    setFocusPolicy(Qt::StrongFocus);
  }

 protected:
  void mousePressEvent(QMouseEvent* e) override { tool_->mousePress(e, view_); }
  void mouseMoveEvent(QMouseEvent* e) override { tool_->mouseMove(e, view_); }
  void mouseReleaseEvent(QMouseEvent* e) override { tool_->mouseRelease(e, view_); }
  void keyPressEvent(QKeyEvent* e) override { tool_->keyPress(e, view_); }

 private:
  ViewportTool* tool_;
  ViewContext view_;
};

// A grid with anisotropic spacing (1, 2, 0.5), an offset origin and a rotated orientation.
GridSpec testGrid() {
  GridSpec g;
  g.dims = glm::ivec3(24, 14, 48);
  g.spacing = glm::vec3(1.f, 2.f, 0.5f);
  g.origin = glm::vec3(-9.3f, -11.7f, -10.1f);
  g.direction = glm::mat3(
      glm::rotate(glm::mat4(1.f), glm::radians(25.f), glm::normalize(glm::vec3(1.f, 2.f, 3.f))));
  return g;
}

// Scalars in data units [-1000, 1000]: a ramp along i, so a value range selects index slabs.
std::shared_ptr<const Volume> testVolume(const GridSpec& g) {
  auto v = std::make_shared<Volume>();
  v->name = "test";
  v->valueMin = -1000.0;
  v->valueMax = 1000.0;
  v->normalized = Field3D("volume", g, Precision::FP32);
  for (int k = 0; k < g.dims.z; ++k)
    for (int j = 0; j < g.dims.y; ++j)
      for (int i = 0; i < g.dims.x; ++i)
        v->normalized.set(g.linearIndex(i, j, k),
                          static_cast<float>(i) / static_cast<float>(g.dims.x - 1));
  return v;
}

// World position of a voxel centre, written out from the definition in double precision.
glm::dvec3 voxelCentre(const GridSpec& g, int i, int j, int k) {
  const glm::dmat3 d(g.direction);
  const glm::dvec3 s(g.spacing);
  return glm::dvec3(g.origin) + d[0] * (double(i) * s.x) + d[1] * (double(j) * s.y) +
         d[2] * (double(k) * s.z);
}

double distanceToSegment(glm::dvec3 p, glm::dvec3 a, glm::dvec3 b) {
  const glm::dvec3 ab = b - a;
  const double len2 = glm::dot(ab, ab);
  const double t = len2 > 0.0 ? std::clamp(glm::dot(p - a, ab) / len2, 0.0, 1.0) : 0.0;
  return glm::length(p - (a + t * ab));
}

// Voxels within `radius` of the polyline through `points`; `minMargin` receives the smallest
// |distance - radius| (a test whose voxels sit on the brush's boundary would be ambiguous).
std::vector<bool> expectedStroke(const GridSpec& g, const std::vector<glm::vec3>& points,
                                 double radius, double* minMargin) {
  std::vector<bool> out(g.voxelCount(), false);
  double margin = 1e30;
  for (int k = 0; k < g.dims.z; ++k)
    for (int j = 0; j < g.dims.y; ++j)
      for (int i = 0; i < g.dims.x; ++i) {
        const glm::dvec3 p = voxelCentre(g, i, j, k);
        double d = 1e30;
        for (size_t s = 0; s < points.size(); ++s)
          d = std::min(d, distanceToSegment(p, glm::dvec3(points[s]),
                                            glm::dvec3(points[s == 0 ? 0 : s - 1])));
        margin = std::min(margin, std::abs(d - radius));
        out[g.linearIndex(i, j, k)] = d <= radius;
      }
  if (minMargin) *minMargin = margin;
  return out;
}

size_t countSet(const SessionMask& m) {
  size_t n = 0;
  for (size_t i = 0; i < m.voxelCount(); ++i) n += m.get(i) ? 1 : 0;
  return n;
}

bool sameAs(const SessionMask& m, const std::vector<bool>& expected, size_t* mismatches) {
  size_t bad = 0;
  for (size_t i = 0; i < expected.size(); ++i) bad += m.get(i) != expected[i] ? 1 : 0;
  if (mismatches) *mismatches = bad;
  return bad == 0;
}

// A sphere of radius 7 (centre c) as the base SDF of a visible context surface, on `g`.
std::shared_ptr<const Field3D> sphereSdf(const GridSpec& g, glm::vec3 c, float radius) {
  auto phi = std::make_shared<Field3D>("sphere", g, Precision::FP32);
  for (int k = 0; k < g.dims.z; ++k)
    for (int j = 0; j < g.dims.y; ++j)
      for (int i = 0; i < g.dims.x; ++i)
        phi->set(g.linearIndex(i, j, k),
                 glm::length(g.indexToWorld(glm::vec3(float(i), float(j), float(k))) - c) - radius);
  return phi;
}

constexpr float kSphereRadius = 6.3f;
const glm::vec3 kSphereCentre(0.4f, -0.3f, 0.2f);

ViewContext sphereView(bool surfaceVisible = true) {
  const GridSpec g = testGrid();
  auto scene = std::make_shared<SceneSnapshot>();
  scene->volume = testVolume(g);
  scene->transferFunction.opacity = {{-1000.0, 0.f}, {1000.0, 0.f}};  // transparent volume
  scene->transferFunction.color = {{-1000.0, glm::vec3(1.f)}};
  scene->surfaceBases.push_back(sphereSdf(g, kSphereCentre, kSphereRadius));
  ContextSurfaceSpec spec;
  spec.source = "test:sphere";
  spec.visible = surfaceVisible;
  scene->surfaces.push_back(spec);
  ViewContext view;
  view.camera = Camera::orbit(glm::vec3(0.f), 30.f, 20.f, 60.f);
  view.camera.fovYDegrees = 25.f;
  view.imageSize = QSize(240, 160);
  view.scene = scene;
  return view;
}

// The renderer's ray, written out from its definition: vertical field of view, aspect
// width / height, u = 2x / W - 1 to the right, v = 1 - 2y / H upwards.
glm::dvec3 analyticRayDirection(const ViewContext& view, QPointF pos) {
  const glm::dvec3 fwd = glm::normalize(glm::dvec3(view.camera.target - view.camera.eye));
  const glm::dvec3 right = glm::normalize(glm::cross(fwd, glm::dvec3(view.camera.up)));
  const glm::dvec3 up = glm::cross(right, fwd);
  const double tanY = std::tan(0.5 * double(view.camera.fovYDegrees) * std::numbers::pi / 180.0);
  const double w = view.imageSize.width(), h = view.imageSize.height();
  const double u = 2.0 * pos.x() / w - 1.0, v = 1.0 - 2.0 * pos.y() / h;
  return glm::normalize(fwd + u * tanY * (w / h) * right + v * tanY * up);
}

}  // namespace

class TestMaskPainting : public QObject {
  Q_OBJECT
 private slots:
  void strokeMarksExactlyTheVoxelsWithinTheWorldRadius();
  void undoAndRedoAreBitwiseExact();
  void cancelledStrokeLeavesNoTrace();
  void memoryCapDropsTheOldestEntries();
  void valueRangeLimitsTheChange();
  void pickingHitsTheSphereSdfAnalytically();
  void toolStrokeThroughMouseEvents();
  void escapeMidStrokeThroughTheTool();
};

void TestMaskPainting::strokeMarksExactlyTheVoxelsWithinTheWorldRadius() {
  const GridSpec g = testGrid();
  MaskEditor editor(testVolume(g));
  QCOMPARE(editor.mask().dims, g.dims);
  QCOMPARE(countSet(editor.mask()), size_t(0));
  editor.setRadius(3.3f);
  // A fast drag: points 9 to 13 world units apart, far more than the brush's diameter.
  const std::vector<glm::vec3> points = {
      {-4.1f, -2.2f, -3.3f}, {3.7f, 1.9f, 1.1f}, {-1.3f, 6.2f, 7.9f}, {2.2f, -5.1f, 5.3f}};
  editor.beginStroke();
  for (glm::vec3 p : points) editor.addStrokePoint(p);
  QVERIFY(editor.endStroke());

  double margin = 0.0;
  const auto expected = expectedStroke(g, points, 3.3, &margin);
  QVERIFY2(margin > 1e-4, "no voxel centre may lie on the brush's boundary");
  size_t bad = 0;
  QVERIFY2(sameAs(editor.mask(), expected, &bad), qPrintable(QString("%1 voxels differ").arg(bad)));
  QVERIFY(countSet(editor.mask()) > 500);

  // The spacing is honoured: along the grid's j axis (2 mm) a voxel 2 steps away is 4 mm off
  // and outside the 3.3 mm brush, along i (1 mm) 3 steps away is 3 mm and inside.
  MaskEditor single(testVolume(g));
  single.setRadius(3.3f);
  single.beginStroke();
  single.addStrokePoint(g.indexToWorld(glm::vec3(10.f, 7.f, 20.f)));
  single.endStroke();
  QVERIFY(single.mask().get(g.linearIndex(13, 7, 20)));
  QVERIFY(!single.mask().get(g.linearIndex(14, 7, 20)));
  QVERIFY(single.mask().get(g.linearIndex(10, 8, 20)));
  QVERIFY(!single.mask().get(g.linearIndex(10, 9, 20)));
  QVERIFY(single.mask().get(g.linearIndex(10, 7, 26)));  // 0.5 mm along k: 3 mm
  QVERIFY(!single.mask().get(g.linearIndex(10, 7, 27)));
}

void TestMaskPainting::undoAndRedoAreBitwiseExact() {
  const GridSpec g = testGrid();
  MaskEditor editor(testVolume(g));
  const SessionMask empty = editor.mask();
  editor.setRadius(4.1f);
  editor.beginStroke();
  editor.addStrokePoint({-3.f, 0.f, 0.f});
  editor.addStrokePoint({3.f, 1.f, 2.f});
  editor.endStroke();
  const SessionMask afterFirst = editor.mask();

  editor.setMode(MaskEditor::Mode::Erase);
  editor.setRadius(2.2f);
  editor.beginStroke();
  editor.addStrokePoint({0.f, 0.5f, 1.f});
  editor.addStrokePoint({0.f, 6.f, 1.f});
  editor.endStroke();
  const SessionMask afterSecond = editor.mask();
  QVERIFY(countSet(afterSecond) < countSet(afterFirst));
  QVERIFY(countSet(afterSecond) > 0);

  editor.setMode(MaskEditor::Mode::Paint);
  QVERIFY(editor.clear());
  QCOMPARE(countSet(editor.mask()), size_t(0));
  QCOMPARE(editor.undoCount(), size_t(3));

  QVERIFY(editor.undo());
  QVERIFY(editor.mask() == afterSecond);
  QVERIFY(editor.undo());
  QVERIFY(editor.mask() == afterFirst);
  QVERIFY(editor.undo());
  QVERIFY(editor.mask() == empty);
  QVERIFY(!editor.canUndo());
  QVERIFY(!editor.undo());

  QVERIFY(editor.redo());
  QVERIFY(editor.mask() == afterFirst);
  QVERIFY(editor.redo());
  QVERIFY(editor.mask() == afterSecond);
  QVERIFY(editor.undo());
  QVERIFY(editor.mask() == afterFirst);
  // A new stroke drops what could have been redone.
  editor.beginStroke();
  editor.addStrokePoint({5.f, 5.f, 5.f});
  editor.endStroke();
  QVERIFY(!editor.canRedo());
  QVERIFY(editor.undo());
  QVERIFY(editor.mask() == afterFirst);
}

void TestMaskPainting::cancelledStrokeLeavesNoTrace() {
  const GridSpec g = testGrid();
  MaskEditor editor(testVolume(g));
  editor.setRadius(3.f);
  editor.beginStroke();
  editor.addStrokePoint({0.f, 0.f, 0.f});
  editor.endStroke();
  const SessionMask before = editor.mask();
  const size_t bytesBefore = editor.bytesUsed();

  editor.setMode(MaskEditor::Mode::Erase);
  editor.beginStroke();
  editor.addStrokePoint({1.f, 0.f, 0.f});   // erases part of the first stroke
  editor.setMode(MaskEditor::Mode::Paint);  // the stroke keeps erasing
  editor.addStrokePoint({6.f, 3.f, 0.f});
  QVERIFY(editor.mask() != before);
  QVERIFY(editor.cancelStroke());
  QVERIFY(editor.mask() == before);
  QCOMPARE(editor.undoCount(), size_t(1));
  QCOMPARE(editor.bytesUsed(), bytesBefore);
  // Undo during a stroke cancels just that stroke.
  editor.beginStroke();
  editor.addStrokePoint({-5.f, 2.f, 1.f});
  QVERIFY(editor.undo());
  QVERIFY(!editor.stroking());
  QVERIFY(editor.mask() == before);
  QCOMPARE(editor.undoCount(), size_t(1));
  QVERIFY(editor.undo());
  QCOMPARE(countSet(editor.mask()), size_t(0));
}

void TestMaskPainting::memoryCapDropsTheOldestEntries() {
  const GridSpec g = testGrid();
  MaskEditor editor(testVolume(g));
  editor.setRadius(2.5f);
  std::vector<SessionMask> states{editor.mask()};
  std::vector<size_t> sizes;
  for (int s = 0; s < 4; ++s) {
    const size_t before = editor.bytesUsed();
    editor.beginStroke();
    editor.addStrokePoint({-6.f + 4.f * float(s), 0.f, 0.f});
    editor.endStroke();
    sizes.push_back(editor.bytesUsed() - before);
    states.push_back(editor.mask());
  }
  QCOMPARE(editor.undoCount(), size_t(4));
  QCOMPARE(editor.bytesUsed(), sizes[0] + sizes[1] + sizes[2] + sizes[3]);

  // Room for the last two entries only.
  editor.setMemoryCap(sizes[2] + sizes[3]);
  QCOMPARE(editor.undoCount(), size_t(2));
  QVERIFY(editor.bytesUsed() <= editor.memoryCap());
  QVERIFY(editor.undo());
  QVERIFY(editor.mask() == states[3]);
  QVERIFY(editor.undo());
  QVERIFY(editor.mask() == states[2]);
  QVERIFY(!editor.canUndo());  // the two oldest strokes were dropped, their voxels stay
  QVERIFY(editor.redo());
  QVERIFY(editor.redo());
  QVERIFY(editor.mask() == states[4]);

  // A new stroke under the cap pushes the oldest remaining entry out.
  editor.beginStroke();
  editor.addStrokePoint({0.f, 5.f, 4.f});
  editor.endStroke();
  QVERIFY(editor.bytesUsed() <= editor.memoryCap());
  QVERIFY(editor.undoCount() <= size_t(2));
  QVERIFY(editor.undo());
  QVERIFY(editor.mask() == states[4]);
}

void TestMaskPainting::valueRangeLimitsTheChange() {
  const GridSpec g = testGrid();
  auto volume = testVolume(g);
  MaskEditor editor(volume);
  editor.setRadius(6.07f);
  const double lo = -300.0, hi = 250.0;
  editor.setValueRange(std::make_pair(lo, hi));
  const std::vector<glm::vec3> points = {{0.3f, 0.1f, -0.2f}};
  editor.beginStroke();
  editor.addStrokePoint(points[0]);
  editor.endStroke();
  double margin = 0.0;
  auto expected = expectedStroke(g, points, 6.07, &margin);
  QVERIFY(margin > 1e-4);
  size_t inSphere = 0, kept = 0;
  for (int k = 0; k < g.dims.z; ++k)
    for (int j = 0; j < g.dims.y; ++j)
      for (int i = 0; i < g.dims.x; ++i) {
        const size_t v = g.linearIndex(i, j, k);
        const double value = -1000.0 + 2000.0 * double(i) / double(g.dims.x - 1);
        inSphere += expected[v] ? 1 : 0;
        expected[v] = expected[v] && value >= lo && value <= hi;
        kept += expected[v] ? 1 : 0;
      }
  QVERIFY(kept > 0 && kept < inSphere);
  size_t bad = 0;
  QVERIFY2(sameAs(editor.mask(), expected, &bad), qPrintable(QString("%1 voxels differ").arg(bad)));

  // Erasing honours the range too: a full-range paint, then a range-limited erase.
  editor.setValueRange(std::nullopt);
  editor.beginStroke();
  editor.addStrokePoint(points[0]);
  editor.endStroke();
  editor.setValueRange(std::make_pair(lo, hi));
  editor.setMode(MaskEditor::Mode::Erase);
  editor.beginStroke();
  editor.addStrokePoint(points[0]);
  editor.endStroke();
  QCOMPARE(countSet(editor.mask()), inSphere - kept);
}

void TestMaskPainting::pickingHitsTheSphereSdfAnalytically() {
  const ViewContext view = sphereView();
  const float halfVoxel = 0.5f * view.scene->grid()->minSpacing();
  const glm::dvec3 c(kSphereCentre);
  const glm::dvec3 eye(view.camera.eye);
  int hits = 0, misses = 0;
  for (int y = 4; y < view.imageSize.height(); y += 5)
    for (int x = 3; x < view.imageSize.width(); x += 7) {
      const QPointF pos(x + 0.37, y + 0.61);
      // The ray matches the renderer's definition.
      const auto ray = worldRay(view, pos);
      QVERIFY(ray);
      const glm::dvec3 d = analyticRayDirection(view, pos);
      QVERIFY(glm::length(glm::dvec3(ray->direction) - d) < 1e-5);
      // Analytic first intersection with the sphere.
      const glm::dvec3 oc = eye - c;
      const double b = glm::dot(oc, d);
      const double disc = b * b - (glm::dot(oc, oc) - double(kSphereRadius) * kSphereRadius);
      const auto hit = pickWorldPoint(view, pos);
      if (disc < 0.0) {
        QVERIFY(!hit);  // the volume is transparent: nothing else to hit
        ++misses;
        continue;
      }
      const double t = -b - std::sqrt(disc);
      const glm::dvec3 expected = eye + t * d;
      // Grazing rays: the SDF's trilinear zero set may differ from the sphere's tangent.
      if (disc < 16.0) continue;
      QVERIFY2(hit, qPrintable(QString("no hit at %1, %2").arg(x).arg(y)));
      const double error = glm::length(glm::dvec3(*hit) - expected);
      QVERIFY2(error < halfVoxel, qPrintable(QString("off by %1").arg(error)));
      // projectToWidget inverts worldRay.
      const auto back = projectToWidget(view, *hit);
      QVERIFY(back);
      QVERIFY(std::abs(back->x() - pos.x()) < 1e-2 && std::abs(back->y() - pos.y()) < 1e-2);
      ++hits;
    }
  qInfo("picking: %d hits, %d misses", hits, misses);
  QVERIFY(hits > 20);
  QVERIFY(misses > 10);

  // An invisible surface is not picked; the volume is, where it is opaque enough.
  ViewContext hidden = sphereView(false);
  const QPointF centre(120.0, 80.0);
  QVERIFY(!pickWorldPoint(hidden, centre));
  auto scene = std::make_shared<SceneSnapshot>(*hidden.scene);
  hidden.scene = scene;
  // The ramp's value (linear in i, clamped at the outer voxel centres) along the ray, inside
  // the grid's cells, written out from the volume's definition.
  const GridSpec& g = *scene->grid();
  const glm::dvec3 d = analyticRayDirection(hidden, centre);
  std::vector<std::pair<glm::dvec3, double>> samples;
  for (double t = 0.0; t < 200.0; t += 0.005) {
    const glm::dvec3 p = eye + t * d;
    const glm::vec3 idx = g.worldToIndex(glm::vec3(p));
    if (glm::any(glm::lessThan(idx, glm::vec3(-0.5f))) ||
        glm::any(glm::greaterThan(idx, glm::vec3(g.dims) - 0.5f)))
      continue;
    const double i = std::clamp(double(idx.x), 0.0, double(g.dims.x - 1));
    samples.emplace_back(p, -1000.0 + 2000.0 * i / double(g.dims.x - 1));
  }
  QVERIFY(samples.size() > 100);
  double vMax = -1e30, vMin = 1e30;
  for (const auto& s : samples) {
    vMax = std::max(vMax, s.second);
    vMin = std::min(vMin, s.second);
  }
  QVERIFY2(vMax - vMin > 200.0, "the ray must cross the ramp");
  // Opaque on the far side of the middle of the ray's value range (the side the ray goes to):
  // the opacity passes 0.3 at 2/3 of the 2-unit ramp of the transfer function.
  const double mid = 0.5 * (vMin + vMax);
  const bool rising = samples.back().second > samples.front().second;
  if (rising)
    scene->transferFunction.opacity = {
        {-1000.0, 0.f}, {mid - 1.0, 0.f}, {mid + 1.0, 0.9f}, {1000.0, 0.9f}};
  else
    scene->transferFunction.opacity = {
        {-1000.0, 0.9f}, {mid - 1.0, 0.9f}, {mid + 1.0, 0.f}, {1000.0, 0.f}};
  const double threshold = rising ? mid - 1.0 + 2.0 / 3.0 : mid + 1.0 - 2.0 / 3.0;
  std::optional<glm::dvec3> expected;
  for (const auto& s : samples)
    if (!expected && (rising ? s.second > threshold : s.second < threshold)) expected = s.first;
  QVERIFY(expected);
  const auto hit = pickWorldPoint(hidden, centre);
  QVERIFY(hit);
  const double error = glm::length(glm::dvec3(*hit) - *expected);
  QVERIFY2(error < halfVoxel, qPrintable(QString("volume hit off by %1").arg(error)));
}

void TestMaskPainting::toolStrokeThroughMouseEvents() {
  const ViewContext view = sphereView();
  MaskPaintTool tool;
  tool.setRadius(2.1f);
  tool.setLiveUpdateInterval(1000000);  // only the stroke's end emits
  QSignalSpy changed(&tool, &MaskPaintTool::maskChanged);
  ToolHost host(&tool, view);
  host.show();

  const std::vector<QPoint> path = {{100, 70}, {125, 78}, {140, 95}};
  QTest::mousePress(&host, Qt::LeftButton, {}, path[0]);
  for (size_t i = 1; i < path.size(); ++i) QTest::mouseMove(&host, path[i]);
  QTest::mouseRelease(&host, Qt::LeftButton, {}, path.back());
  QVERIFY(tool.canUndo());
  QCOMPARE(changed.count(), 1);

  // The voxels are those within the radius of the picked points' polyline (the release
  // repeats the last point).
  std::vector<glm::vec3> points;
  for (QPoint p : path) {
    const auto hit = pickWorldPoint(view, QPointF(p));
    QVERIFY(hit);
    points.push_back(*hit);
  }
  double margin = 0.0;
  const auto expected = expectedStroke(*view.scene->grid(), points, 2.1, &margin);
  auto mask = changed.last().at(0).value<std::shared_ptr<const SessionMask>>();
  QVERIFY(mask);
  size_t bad = 0;
  sameAs(*mask, expected, &bad);
  QVERIFY2(bad <= (margin < 1e-4 ? 2u : 0u), qPrintable(QString("%1 voxels differ").arg(bad)));
  QVERIFY(countSet(*mask) > 50);

  // Ctrl-drag erases; undo and redo through the tool's slots.
  const SessionMask painted = *mask;
  QTest::mousePress(&host, Qt::LeftButton, Qt::ControlModifier, path[1]);
  QTest::mouseRelease(&host, Qt::LeftButton, Qt::ControlModifier, path[1]);
  QVERIFY(countSet(*tool.mask()) < countSet(painted));
  tool.undo();
  QVERIFY(*tool.mask() == painted);
  QVERIFY(*changed.last().at(0).value<std::shared_ptr<const SessionMask>>() == painted);
  tool.redo();
  QVERIFY(countSet(*tool.mask()) < countSet(painted));
  tool.clear();
  QCOMPARE(countSet(*tool.mask()), size_t(0));
  tool.undo();
  QVERIFY(countSet(*tool.mask()) > 0);
}

void TestMaskPainting::escapeMidStrokeThroughTheTool() {
  const ViewContext view = sphereView();
  MaskPaintTool tool;
  tool.setRadius(2.5f);
  tool.setLiveUpdateInterval(0);  // every point emits: listeners see the stroke live
  QSignalSpy changed(&tool, &MaskPaintTool::maskChanged);
  ToolHost host(&tool, view);
  host.show();
  host.setFocus();

  QTest::mousePress(&host, Qt::LeftButton, {}, QPoint(110, 75));
  QTest::mouseRelease(&host, Qt::LeftButton, {}, QPoint(110, 75));
  const SessionMask before = *tool.mask();
  QVERIFY(countSet(before) > 0);

  QTest::mousePress(&host, Qt::LeftButton, {}, QPoint(120, 80));
  QTest::mouseMove(&host, QPoint(135, 90));
  QVERIFY(tool.stroking());
  QVERIFY(*changed.last().at(0).value<std::shared_ptr<const SessionMask>>() != before);
  QTest::keyClick(&host, Qt::Key_Escape);
  QVERIFY(!tool.stroking());
  QVERIFY(*tool.mask() == before);
  QVERIFY(*changed.last().at(0).value<std::shared_ptr<const SessionMask>>() == before);
  // The release after the cancel paints nothing; one undo entry (the first stroke) remains.
  QTest::mouseRelease(&host, Qt::LeftButton, {}, QPoint(135, 90));
  QVERIFY(*tool.mask() == before);
  QCOMPARE(tool.editor().undoCount(), size_t(1));
  tool.undo();
  QCOMPARE(countSet(*tool.mask()), size_t(0));
}

QTEST_MAIN(TestMaskPainting)
#include "test_mask_painting.moc"
