// The workstation's window as a user first meets it: the 3D view takes most of the width (at
// least 60 % at 1280 and 1600 pixels, the side panels tabbed in one column), a rearranged layout
// comes back in the next run (a damaged layout file is ignored) and "Reset panel layout"
// restores the default; files named on the command line are sorted into a volume or session and
// context surfaces, a mesh among them is added to the scene, and a scripted run given a file it
// cannot read ends at once with a non-zero exit and a message naming the file.
#include <memory>

#include <QAction>
#include <QDir>
#include <QDockWidget>
#include <QFile>
#include <QMenu>
#include <QMenuBar>
#include <QProcess>
#include <QProcessEnvironment>
#include <QTest>

#include <visopt/engine.h>

#include "command_line_files.h"
#include "main_window.h"
#include "viewport_widget.h"

using namespace visopt;
using namespace visopt::ws;

namespace {

QString freshDir(const QString& name) {
  const QString dir = QStringLiteral(VISOPT_TEST_TMP) + QStringLiteral("/window-layout/") + name;
  QDir(dir).removeRecursively();
  QDir().mkpath(dir);
  return dir;
}

std::unique_ptr<MainWindow> makeWindow(const QString& stateDir, int width, int height) {
  auto w = std::make_unique<MainWindow>(Precision::FP32, stateDir);
  w->setInteractive(false);
  w->setOptimizationRunning(false);
  w->resize(width, height);
  return w;
}

QDockWidget* panel(MainWindow& w, const QString& title) {
  for (QDockWidget* d : w.findChildren<QDockWidget*>())
    if (d->windowTitle() == title) return d;
  return nullptr;
}

const QStringList kPanels = {QStringLiteral("Transfer function"), QStringLiteral("Importance"),
                             QStringLiteral("Surfaces"),          QStringLiteral("Optimisation"),
                             QStringLiteral("Deviation"),         QStringLiteral("Hotspot")};

QAction* menuAction(MainWindow& w, const QString& text) {
  for (QAction* menu : w.menuBar()->actions())
    if (menu->menu())
      for (QAction* a : menu->menu()->actions())
        if (a->text().remove(QLatin1Char('&')) == text) return a;
  return nullptr;
}

}  // namespace

class TestWindowLayout : public QObject {
  Q_OBJECT

 private slots:
  void viewGetsMostOfTheWidth_data();
  void viewGetsMostOfTheWidth();
  void layoutIsRememberedAndCanBeReset();
  void damagedLayoutFileIsIgnored();
  void commandLineFilesAreSorted();
  void meshOnTheCommandLineBecomesAContextSurface();
  void unreadableFileEndsAScriptedRun();
};

void TestWindowLayout::viewGetsMostOfTheWidth_data() {
  QTest::addColumn<int>("width");
  QTest::addColumn<int>("height");
  QTest::newRow("1280x800") << 1280 << 800;
  QTest::newRow("1600x1000") << 1600 << 1000;
  QTest::newRow("1920x1080") << 1920 << 1080;
}

void TestWindowLayout::viewGetsMostOfTheWidth() {
  QFETCH(int, width);
  QFETCH(int, height);
  auto w = makeWindow(freshDir(QStringLiteral("width-%1").arg(width)), width, height);
  w->show();
  QVERIFY(QTest::qWaitForWindowExposed(w.get()));
  QCoreApplication::processEvents();
  const int view = w->viewport()->width();
  QVERIFY2(view >= int(0.6 * double(w->width())),
           qPrintable(QStringLiteral("the 3D view is %1 of %2 pixels wide").arg(view).arg(width)));
  // Every panel is there, docked, tabbed with the other four.
  for (const QString& title : kPanels) {
    QDockWidget* d = panel(*w, title);
    QVERIFY2(d, qPrintable(title));
    QVERIFY(!d->isFloating());
    QCOMPARE(w->dockWidgetArea(d), Qt::RightDockWidgetArea);
    QCOMPARE(w->tabifiedDockWidgets(d).size(), kPanels.size() - 1);
  }
}

void TestWindowLayout::layoutIsRememberedAndCanBeReset() {
  const QString dir = freshDir(QStringLiteral("remembered"));
  {
    auto w = makeWindow(dir, 1400, 900);
    w->show();
    QVERIFY(QTest::qWaitForWindowExposed(w.get()));
    panel(*w, QStringLiteral("Deviation"))->hide();
    panel(*w, QStringLiteral("Optimisation"))->setFloating(true);
    w->close();
  }
  QVERIFY(QFile::exists(dir + QStringLiteral("/window-layout.bin")));
  auto w = makeWindow(dir, 1400, 900);
  w->show();
  QVERIFY(QTest::qWaitForWindowExposed(w.get()));
  QVERIFY(panel(*w, QStringLiteral("Deviation"))->isHidden());
  QVERIFY(panel(*w, QStringLiteral("Optimisation"))->isFloating());

  QAction* reset = menuAction(*w, QStringLiteral("Reset panel layout"));
  QVERIFY(reset);
  reset->trigger();
  QCoreApplication::processEvents();
  for (const QString& title : kPanels) {
    QDockWidget* d = panel(*w, title);
    QVERIFY2(!d->isHidden() && !d->isFloating(), qPrintable(title));
    QCOMPARE(w->tabifiedDockWidgets(d).size(), kPanels.size() - 1);
  }
  QVERIFY(w->viewport()->width() >= int(0.6 * double(w->width())));
}

void TestWindowLayout::damagedLayoutFileIsIgnored() {
  const QString dir = freshDir(QStringLiteral("damaged"));
  QFile f(dir + QStringLiteral("/window-layout.bin"));
  QVERIFY(f.open(QIODevice::WriteOnly));
  f.write("not a layout at all");
  f.close();
  auto w = makeWindow(dir, 1280, 800);
  w->show();
  QVERIFY(QTest::qWaitForWindowExposed(w.get()));
  QVERIFY(w->viewport()->width() >= int(0.6 * 1280));
  for (const QString& title : kPanels) QVERIFY(!panel(*w, title)->isHidden());
}

void TestWindowLayout::commandLineFilesAreSorted() {
  const QString dicomDir = freshDir(QStringLiteral("dicom-folder"));
  CommandLineFiles f = sortCommandLineFiles(
      {QStringLiteral("head.nii.gz"), QStringLiteral("skin.PLY"), QStringLiteral("b.obj"),
       QStringLiteral("c.off"), QStringLiteral("d.stl"), QStringLiteral("e.vdb")});
  QVERIFY(f.error.isEmpty());
  QCOMPARE(f.volume, QStringLiteral("head.nii.gz"));
  QVERIFY(f.session.isEmpty());
  QCOMPARE(f.surfaces, QStringList({QStringLiteral("mesh:skin.PLY"), QStringLiteral("mesh:b.obj"),
                                    QStringLiteral("mesh:c.off"), QStringLiteral("mesh:d.stl"),
                                    QStringLiteral("vdb:e.vdb")}));

  f = sortCommandLineFiles({QStringLiteral("work.visopt-session")});
  QCOMPARE(f.session, QStringLiteral("work.visopt-session"));
  QVERIFY(f.volume.isEmpty());
  f = sortCommandLineFiles({QStringLiteral("old.json")});
  QCOMPARE(f.session, QStringLiteral("old.json"));

  f = sortCommandLineFiles({dicomDir});  // a folder is a DICOM series, whatever its name
  QCOMPARE(f.volume, dicomDir);

  f = sortCommandLineFiles({QStringLiteral("a.nii"), QStringLiteral("b.mhd")});
  QVERIFY(f.error.contains(QStringLiteral("b.mhd")) && f.error.contains(QStringLiteral("a.nii")));
  f = sortCommandLineFiles({QStringLiteral("a.nii"), QStringLiteral("s.visopt-session")});
  QVERIFY(!f.error.isEmpty());

  f = sortCommandLineFiles({});
  QVERIFY(f.error.isEmpty() && f.volume.isEmpty() && f.session.isEmpty() && f.surfaces.isEmpty());

  // The options add their scene, or refuse a second one (it used to open one silently).
  f = sortCommandLineFiles({QStringLiteral("skin.ply")});
  addSceneOptions(f, {QStringLiteral("a.nii"), {}, {}});
  QVERIFY(f.error.isEmpty());
  QCOMPARE(f.volume, QStringLiteral("a.nii"));
  f = sortCommandLineFiles({});
  addSceneOptions(f, {{}, {}, QStringLiteral("builtin:mixer")});
  QCOMPARE(f.scene, QStringLiteral("builtin:mixer"));
  f = sortCommandLineFiles({QStringLiteral("b.nii")});
  addSceneOptions(f, {QStringLiteral("a.nii"), {}, {}});
  QVERIFY(f.error.contains(QStringLiteral("--volume a.nii")) &&
          f.error.contains(QStringLiteral("b.nii")));
  f = sortCommandLineFiles({});
  addSceneOptions(f, {QStringLiteral("a.nii"), {}, QStringLiteral("builtin:mixer")});
  QVERIFY(f.error.contains(QStringLiteral("--scene builtin:mixer")));
  f = sortCommandLineFiles({QStringLiteral("w.visopt-session")});
  addSceneOptions(f, {{}, QStringLiteral("v.visopt-session"), {}});
  QVERIFY(!f.error.isEmpty());
}

void TestWindowLayout::meshOnTheCommandLineBecomesAContextSurface() {
  const QString dir = freshDir(QStringLiteral("mesh"));
  // A closed cube (OFF) inside the built-in scene's box.
  const QString mesh = dir + QStringLiteral("/cube.off");
  QFile f(mesh);
  QVERIFY(f.open(QIODevice::WriteOnly));
  f.write(
      "OFF\n8 12 0\n-0.2 -0.2 -0.2\n0.2 -0.2 -0.2\n0.2 0.2 -0.2\n-0.2 0.2 -0.2\n"
      "-0.2 -0.2 0.2\n0.2 -0.2 0.2\n0.2 0.2 0.2\n-0.2 0.2 0.2\n"
      "3 0 2 1\n3 0 3 2\n3 4 5 6\n3 4 6 7\n3 0 1 5\n3 0 5 4\n"
      "3 2 3 7\n3 2 7 6\n3 1 2 6\n3 1 6 5\n3 0 4 7\n3 0 7 3\n");
  f.close();
  const CommandLineFiles files = sortCommandLineFiles({mesh});
  QCOMPARE(files.surfaces.size(), 1);

  auto w = makeWindow(dir + QStringLiteral("/state"), 1280, 800);
  int errors = 0;
  connect(w.get(), &MainWindow::errorShown, [&](const QString& m) {
    qWarning("%s", qPrintable(m));
    ++errors;
  });
  w->openBuiltinScene(QStringLiteral("shepp-logan"), 32);
  const size_t before = 1;  // the built-in scene brings one context surface of its own
  w->addContextSurface(files.surfaces.front());
  QVERIFY(w->controller()->waitIdle(120000));
  QCoreApplication::processEvents();
  QCOMPARE(errors, 0);
  size_t count = 0;
  std::string last;
  w->controller()->call([&](Engine& e) {
    count = e.contextSurfaces().size();
    last = e.contextSurfaces().back().source;
  });
  QCOMPARE(count, before + 1);
  QCOMPARE(QString::fromStdString(last), files.surfaces.front());
}

void TestWindowLayout::unreadableFileEndsAScriptedRun() {
  const QString dir = freshDir(QStringLiteral("unreadable"));
  const QString bad = dir + QStringLiteral("/scan.nii");
  QFile f(bad);
  QVERIFY(f.open(QIODevice::WriteOnly));
  f.write("only a few bytes, no NIfTI header");
  f.close();
  QProcess p;
  QProcessEnvironment env = QProcessEnvironment::systemEnvironment();
  env.insert(QStringLiteral("QT_QPA_PLATFORM"), QStringLiteral("offscreen"));
  p.setProcessEnvironment(env);
  p.setProcessChannelMode(QProcess::MergedChannels);
  p.start(QStringLiteral(VISOPT_WORKSTATION),
          {bad, QStringLiteral("--no-optimize"), QStringLiteral("--screenshot"),
           dir + QStringLiteral("/never.png"), QStringLiteral("--state-dir"),
           dir + QStringLiteral("/state")});
  QVERIFY(p.waitForStarted(30000));
  // It used to wait out --timeout (300 s) for a frame that could not come.
  QVERIFY2(p.waitForFinished(120000), "the scripted run did not end after the error");
  const QString log = QString::fromUtf8(p.readAll());
  QVERIFY2(p.exitCode() != 0, qPrintable(log));
  QVERIFY2(log.contains(bad), qPrintable(log));
  QVERIFY(!QFile::exists(dir + QStringLiteral("/never.png")));

  // Two volumes: refused before anything opens.
  p.start(QStringLiteral(VISOPT_WORKSTATION),
          {bad, bad + QStringLiteral(".other.nii"), QStringLiteral("--state-dir"),
           dir + QStringLiteral("/state")});
  QVERIFY(p.waitForFinished(60000));
  QVERIFY(p.exitCode() != 0);
  QVERIFY(QString::fromUtf8(p.readAll()).contains(QStringLiteral("only one volume or session")));
}

QTEST_MAIN(TestWindowLayout)
#include "test_window_layout.moc"
