// The workstation on a real (virtual) display: visopt-workstation runs under `xvfb-run -a` with the
// xcb platform, opens a built-in scene, optimises until the frame settles and saves both the
// whole window and the viewport as PNG. The window image must have the requested size and show
// the rendered frame: the viewport image appears in it pixel for pixel, and both have many
// distinct colours (not a blank or uniform widget).
#include <algorithm>
#include <cstdint>
#include <unordered_map>
#include <unordered_set>

#include <QDir>
#include <QFile>
#include <QImage>
#include <QProcess>
#include <QProcessEnvironment>
#include <QStandardPaths>
#include <QTest>

namespace {

struct ColourStats {
  size_t distinct = 0;
  double dominantFraction = 1.0;  // share of the most common colour
};

ColourStats colourStats(const QImage& image, const QRect& region) {
  std::unordered_map<QRgb, size_t> counts;
  size_t total = 0;
  for (int y = region.top(); y <= region.bottom(); ++y)
    for (int x = region.left(); x <= region.right(); ++x) {
      ++counts[image.pixel(x, y) & 0xffffffu];
      ++total;
    }
  size_t most = 0;
  for (const auto& [colour, n] : counts) most = std::max(most, n);
  ColourStats s;
  s.distinct = counts.size();
  s.dominantFraction = total > 0 ? double(most) / double(total) : 1.0;
  return s;
}

// Where `part` appears pixel for pixel inside `whole` (top-left corner), or (-1, -1).
QPoint findSubImage(const QImage& whole, const QImage& part) {
  const int w = part.width(), h = part.height();
  if (w > whole.width() || h > whole.height() || w == 0 || h == 0) return {-1, -1};
  // A sparse set of probe pixels first, then the full comparison.
  std::vector<QPoint> probes;
  for (int j = 0; j < 8; ++j)
    for (int i = 0; i < 8; ++i) probes.emplace_back(i * (w - 1) / 7, j * (h - 1) / 7);
  const QRgb first = part.pixel(0, 0) & 0xffffffu;
  for (int oy = 0; oy + h <= whole.height(); ++oy)
    for (int ox = 0; ox + w <= whole.width(); ++ox) {
      if ((whole.pixel(ox, oy) & 0xffffffu) != first) continue;
      bool ok = true;
      for (const QPoint& p : probes)
        if ((whole.pixel(ox + p.x(), oy + p.y()) & 0xffffffu) != (part.pixel(p) & 0xffffffu)) {
          ok = false;
          break;
        }
      if (!ok) continue;
      for (int y = 0; y < h && ok; ++y)
        for (int x = 0; x < w; ++x)
          if ((whole.pixel(ox + x, oy + y) & 0xffffffu) != (part.pixel(x, y) & 0xffffffu)) {
            ok = false;
            break;
          }
      if (ok) return {ox, oy};
    }
  return {-1, -1};
}

}  // namespace

class TestWorkstationScreenshot : public QObject {
  Q_OBJECT

 private slots:
  void windowScreenshotUnderXvfb();
  void sessionOptionOpensTheSession();
};

void TestWorkstationScreenshot::windowScreenshotUnderXvfb() {
  const QString xvfbRun = QStandardPaths::findExecutable(QStringLiteral("xvfb-run"));
  if (xvfbRun.isEmpty())
    QSKIP("xvfb-run not found (install the xvfb and xauth packages): no display to test with");
  const QString dir = QStringLiteral(VISOPT_TEST_TMP) + QStringLiteral("/workstation-screenshot");
  QDir(dir).removeRecursively();
  QVERIFY(QDir().mkpath(dir));
  const QString windowPng = dir + QStringLiteral("/window.png");
  const QString viewportPng = dir + QStringLiteral("/viewport.png");

  QProcessEnvironment env = QProcessEnvironment::systemEnvironment();
  env.remove(QStringLiteral("QT_QPA_PLATFORM"));  // the X server's platform (xcb), not offscreen
  env.remove(QStringLiteral("VISOPT_SESSION_FAULT"));
  QProcess p;
  p.setProgram(xvfbRun);
  p.setArguments({QStringLiteral("-a"), QStringLiteral("-s"),
                  QStringLiteral("-screen 0 1600x1000x24"), QStringLiteral(VISOPT_WORKSTATION),
                  QStringLiteral("--scene"), QStringLiteral("builtin:shepp-logan"),
                  QStringLiteral("--resolution"), QStringLiteral("32"),
                  QStringLiteral("--window-screenshot"), windowPng, QStringLiteral("--screenshot"),
                  viewportPng, QStringLiteral("--size"), QStringLiteral("1280x800"),
                  QStringLiteral("--timeout"), QStringLiteral("600"), QStringLiteral("--state-dir"),
                  dir + QStringLiteral("/state")});
  p.setProcessEnvironment(env);
  p.setProcessChannelMode(QProcess::MergedChannels);
  p.start();
  QVERIFY2(p.waitForStarted(30000), qPrintable(p.errorString()));
  const bool finished = p.waitForFinished(590000);
  const QString log = QString::fromUtf8(p.readAll());
  if (!finished) {
    p.kill();
    p.waitForFinished(10000);
    QFAIL(qPrintable(QStringLiteral("the workstation did not finish:\n") + log));
  }
  QVERIFY2(p.exitStatus() == QProcess::NormalExit && p.exitCode() == 0,
           qPrintable(QStringLiteral("exit code %1:\n%2").arg(p.exitCode()).arg(log)));

  const QImage window(windowPng);
  QVERIFY2(!window.isNull(), qPrintable(QStringLiteral("no readable PNG at ") + windowPng));
  QCOMPARE(window.width(), 1280);
  const QImage viewport(viewportPng);
  QVERIFY2(!viewport.isNull(), qPrintable(QStringLiteral("no readable PNG at ") + viewportPng));
  QVERIFY2(
      viewport.width() >= 200 && viewport.height() >= 200,
      qPrintable(QStringLiteral("viewport %1x%2").arg(viewport.width()).arg(viewport.height())));

  // The rendered frame: many shades, no colour covering (nearly) all of it.
  const ColourStats frame = colourStats(viewport, viewport.rect());
  QVERIFY2(frame.distinct >= 200, qPrintable(QStringLiteral("%1 colours").arg(frame.distinct)));
  QVERIFY2(
      frame.dominantFraction < 0.9,
      qPrintable(QStringLiteral("one colour covers %1 of the frame").arg(frame.dominantFraction)));

  // The window shows that frame, in the viewport, pixel for pixel.
  const QImage window32 = window.convertToFormat(QImage::Format_RGB32);
  const QImage viewport32 = viewport.convertToFormat(QImage::Format_RGB32);
  const QPoint at = findSubImage(window32, viewport32);
  QVERIFY2(at.x() >= 0, "the viewport image is not in the window screenshot");
  const QRect region(at, viewport.size());
  const ColourStats shown = colourStats(window32, region);
  QCOMPARE(shown.distinct, frame.distinct);
  // Around it: the window's widgets (docks, tool bar, menus) in other colours.
  const ColourStats all = colourStats(window32, window32.rect());
  QVERIFY(all.distinct > frame.distinct);
  QVERIFY(region.width() < window.width() && region.height() < window.height());
  // The 3D view gets most of the window (the panels share one tabbed column).
  QVERIFY2(region.width() >= int(0.6 * double(window.width())),
           qPrintable(QStringLiteral("the 3D view is %1 of %2 pixels wide")
                          .arg(region.width())
                          .arg(window.width())));
  // Last, so the checks above run regardless: the window has the size asked for (a taller one
  // means the docks' minimum heights do not fit a 1280x800 screen).
  QVERIFY2(window.height() == 800,
           qPrintable(QStringLiteral("--size 1280x800 gave a window of 1280x%1 (viewport at %2,%3 "
                                     "%4x%5)")
                          .arg(window.height())
                          .arg(at.x())
                          .arg(at.y())
                          .arg(viewport.width())
                          .arg(viewport.height())));
}

// `--session FILE` opens the session (QGuiApplication takes "-session" for X11 session
// management out of argv, so the option used to open the default scene instead): what
// --save-session writes is the session's scene and hotspot settings.
void TestWorkstationScreenshot::sessionOptionOpensTheSession() {
  const QString dir = QStringLiteral(VISOPT_TEST_TMP) + QStringLiteral("/workstation-session");
  QDir(dir).removeRecursively();
  QVERIFY(QDir().mkpath(dir));
  const QString in = dir + QStringLiteral("/in.visopt-session");
  const QString out = dir + QStringLiteral("/out.visopt-session");
  {
    QFile f(in);
    QVERIFY(f.open(QIODevice::WriteOnly));
    f.write(R"({"format":"visopt-session","version":5,)"
            R"("data":{"builtin":"marschner-lobb","resolution":20},)"
            R"("clearView":{"context":{"kind":"iso","isovalue":0.3},)"
            R"("focus":{"kind":"iso","isovalue":0.7},)"
            R"("deeperContexts":[{"kind":"iso","isovalue":0.5}],"weight":0.25}})");
  }
  for (const QString& form : {QStringLiteral("--session"), QStringLiteral("--session=")}) {
    QFile::remove(out);
    QProcessEnvironment env = QProcessEnvironment::systemEnvironment();
    env.insert(QStringLiteral("QT_QPA_PLATFORM"), QStringLiteral("offscreen"));
    QProcess p;
    p.setProgram(QStringLiteral(VISOPT_WORKSTATION));
    QStringList args;
    if (form.endsWith(QLatin1Char('=')))
      args << form + in;
    else
      args << form << in;
    args << QStringLiteral("--save-session") << out << QStringLiteral("--no-optimize")
         << QStringLiteral("--state-dir") << dir + QStringLiteral("/state");
    p.setArguments(args);
    p.setProcessEnvironment(env);
    p.setProcessChannelMode(QProcess::MergedChannels);
    p.start();
    QVERIFY2(p.waitForStarted(30000), qPrintable(p.errorString()));
    QVERIFY2(p.waitForFinished(300000), "the workstation did not finish");
    const QString log = QString::fromUtf8(p.readAll());
    QVERIFY2(p.exitCode() == 0, qPrintable(log));
    QFile f(out);
    QVERIFY2(f.open(QIODevice::ReadOnly), qPrintable(form + QStringLiteral(": no session saved")));
    const QByteArray text = f.readAll();
    QVERIFY2(text.contains("\"marschner-lobb\"") && text.contains("\"resolution\": 20"),
             qPrintable(form + QStringLiteral(": ") + QString::fromUtf8(text.left(300))));
    QVERIFY2(text.contains("\"deeperContexts\""), qPrintable(form));
  }
}

QTEST_MAIN(TestWorkstationScreenshot)
#include "test_workstation_screenshot.moc"
