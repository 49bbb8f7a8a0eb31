// The Hotspot panel: the ClearView settings (Krüger, Schneider, Westermann 2006;
// visopt/clearview.h) that the Hotspot tool renders with. The context and the focus layer are
// each a context surface of the scene, an isosurface of the data (picked on the histogram or
// typed in data units) or the importance's isosurface, and each may have a second one (a context
// layer behind the first, a focus layer of which the nearer is shown; further ones from a
// session or the library are kept as they are); then the measure that keeps the context
// opaque, the two shaders, the hotspot's size, the weights, the border, the light and the volume
// layer. The panel changes nothing itself: it emits settingsEdited, and shows what it is given
// (setSettings), the library's complaint about a combination (setProblem) and the statistics
// of the last frame (setStats).
#pragma once

#include <memory>
#include <vector>

#include <QString>
#include <QWidget>

#include <visopt/clearview.h>
#include <visopt/context_surface.h>

#include "widgets/histogram.h"

class QCheckBox;
class QComboBox;
class QDoubleSpinBox;
class QLabel;
class QPushButton;
class QStackedWidget;

namespace visopt::ws {

// The decimals the panel shows isovalues of data in [lo, hi] with (a thousandth of the range or
// finer, at least one).
int isovalueDecimals(double lo, double hi);

// A strip of the data's histogram (log counts) with a marker at the chosen value: a left click or
// drag picks the value under the cursor.
class IsovaluePicker : public QWidget {
  Q_OBJECT
 public:
  explicit IsovaluePicker(QWidget* parent = nullptr);
  void setHistogram(std::shared_ptr<const Histogram> histogram);
  void setRange(double lo, double hi);
  void setValue(double value);  // emits nothing
  double value() const { return value_; }
  // Geometry (tests click at computed places).
  double valueAtX(double x) const;
  double xOfValue(double value) const;
  QSize sizeHint() const override { return {200, 34}; }
  QSize minimumSizeHint() const override { return {60, 24}; }

 signals:
  void valuePicked(double value);

 protected:
  void paintEvent(QPaintEvent*) override;
  void mousePressEvent(QMouseEvent* event) override;
  void mouseMoveEvent(QMouseEvent* event) override;

 private:
  QRectF plotRect() const;
  std::shared_ptr<const Histogram> histogram_;
  double lo_ = 0.0, hi_ = 1.0, value_ = 0.5;
};

// One layer: its kind and the value that kind uses.
class HotspotLayerEditor : public QWidget {
  Q_OBJECT
 public:
  // `role`: "context" or "focus" (object names and tooltips).
  HotspotLayerEditor(const QString& role, QWidget* parent = nullptr);
  void setSurfaces(const std::vector<ContextSurfaceSpec>& surfaces);
  void setValueRange(double lo, double hi);
  void setHistogram(std::shared_ptr<const Histogram> histogram);
  void setLayer(const ClearViewLayer& layer);  // emits nothing
  // The layer shown; only the member its kind uses differs from ClearViewLayer{}'s.
  ClearViewLayer layer() const;

  QComboBox* kindBox() const { return kind_; }
  QComboBox* surfaceBox() const { return surface_; }
  QDoubleSpinBox* isovalueBox() const { return isovalue_; }
  QDoubleSpinBox* levelBox() const { return level_; }
  IsovaluePicker* picker() const { return picker_; }

 signals:
  void edited();

 private:
  void showKind();
  void fillSurfaces(int keep);

  std::vector<ContextSurfaceSpec> surfaces_;
  double lo_ = 0.0, hi_ = 0.0;  // the value range of the data (none yet: empty)
  int surfaceIndex_ = 0;        // also one the scene lacks (a session's), shown as missing
  QComboBox* kind_ = nullptr;
  QStackedWidget* pages_ = nullptr;
  QComboBox* surface_ = nullptr;
  QDoubleSpinBox* isovalue_ = nullptr;
  IsovaluePicker* picker_ = nullptr;
  QDoubleSpinBox* level_ = nullptr;
};

class HotspotPanel : public QWidget {
  Q_OBJECT
 public:
  explicit HotspotPanel(QWidget* parent = nullptr);

  // What the layers choose from: the scene's context surfaces and the data's value range (data
  // units); the histogram for picking isovalues. The size limits follow the scene's bounding
  // radius (world units).
  void setScene(const std::vector<ContextSurfaceSpec>& surfaces, double valueMin, double valueMax,
                float sceneRadius);
  void setHistogram(std::shared_ptr<const Histogram> histogram);
  // Shows `settings` (width, height and focusPixel are not shown); emits nothing.
  void setSettings(const ClearViewSettings& settings);
  // The settings shown (width, height and focusPixel at their defaults).
  ClearViewSettings settings() const;
  // Empty hides it: what the library said about the last ClearView frame it refused.
  void setProblem(const QString& message);
  QString problem() const;
  // The last ClearView frame's statistics, one line.
  void setStats(const ClearViewStats& stats);
  QString statsText() const;

  HotspotLayerEditor* contextLayer() const { return context_; }
  HotspotLayerEditor* focusLayer() const { return focus_; }
  // The second context and focus layers and the boxes that switch them on.
  HotspotLayerEditor* deeperContextLayer() const { return deeper_; }
  HotspotLayerEditor* secondFocusLayer() const { return secondFocus_; }
  QCheckBox* deeperContextBox() const { return deeperOn_; }
  QCheckBox* secondFocusBox() const { return secondFocusOn_; }

 signals:
  void settingsEdited(const visopt::ClearViewSettings& settings);
  void resetRequested();           // back to the scene's defaults
  void optimiseAroundRequested();  // the hotspot as the importance, then optimise

 private:
  void onEdited();

  bool updating_ = false;
  HotspotLayerEditor* context_ = nullptr;
  HotspotLayerEditor* focus_ = nullptr;
  QCheckBox* deeperOn_ = nullptr;
  HotspotLayerEditor* deeper_ = nullptr;
  QCheckBox* secondFocusOn_ = nullptr;
  HotspotLayerEditor* secondFocus_ = nullptr;
  QComboBox* measure_ = nullptr;
  QComboBox* contextShader_ = nullptr;
  QComboBox* focusShader_ = nullptr;
  QDoubleSpinBox* size_ = nullptr;
  QDoubleSpinBox* weight_ = nullptr;
  QDoubleSpinBox* distanceScale_ = nullptr;
  QCheckBox* border_ = nullptr;
  QDoubleSpinBox* ambient_ = nullptr;
  QComboBox* light_ = nullptr;
  QCheckBox* volumeLayer_ = nullptr;
  QPushButton* reset_ = nullptr;
  QPushButton* optimiseAround_ = nullptr;
  QLabel* problem_ = nullptr;
  QLabel* stats_ = nullptr;
  // The colours and the layers beyond the second of each kind, which the panel does not edit,
  // kept as given.
  ClearViewSettings given_;
};

}  // namespace visopt::ws

#ifndef VISOPT_WS_METATYPE_CLEARVIEW_SETTINGS
#define VISOPT_WS_METATYPE_CLEARVIEW_SETTINGS
Q_DECLARE_METATYPE(visopt::ClearViewSettings)
#endif
