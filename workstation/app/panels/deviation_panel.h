// The deviation view (Himmler & Günther 2026, Fig. 5): context surfaces coloured by how far the
// optimisation moved them from their original shape, |phi0| at the surface, through a colormap over
// [0, max deviation]. The panel edits the view's settings; DeviationLegend shows the colour bar.
#pragma once

#include <QMetaType>
#include <QString>
#include <QStringList>
#include <QWidget>

#include <visopt/colormap.h>

class QCheckBox;
class QComboBox;
class QDoubleSpinBox;

namespace visopt::ws {

enum class DeviationUnit { Voxels, Millimetres };

// A horizontal colour bar over [0, maxValue] with tick labels in the given unit.
class DeviationLegend : public QWidget {
  Q_OBJECT
 public:
  explicit DeviationLegend(QWidget* parent = nullptr);

  void setColormap(Colormap colormap);
  Colormap colormap() const { return colormap_; }
  // The value at the bar's right end and its unit ("vx", "mm").
  void setRange(double maxValue, const QString& unit);
  double maxValue() const { return maxValue_; }
  QString unit() const { return unit_; }

  // The bar's colour at t in [0, 1] as drawn: the colormap's linear RGB, sRGB-encoded.
  QColor colorAt(float t) const;
  // Where the bar is drawn, in widget coordinates.
  QRect barRect() const;
  // The labels under the bar, left to right (0, max/4, ..., max; the last one with the unit).
  QStringList tickLabels() const;

  QSize sizeHint() const override;
  QSize minimumSizeHint() const override;

 protected:
  void paintEvent(QPaintEvent* event) override;

 private:
  Colormap colormap_ = Colormap::Viridis;
  double maxValue_ = 10.0;
  QString unit_ = QStringLiteral("vx");
};

class DeviationPanel : public QWidget {
  Q_OBJECT
 public:
  explicit DeviationPanel(QWidget* parent = nullptr);

  // Shows these settings; emits nothing.
  void setDeviationSettings(bool enabled, Colormap colormap, float maxVoxels);
  bool deviationEnabled() const;
  Colormap colormap() const;
  float maxVoxels() const { return maxVoxels_; }

  // The voxel size in mm (world units); > 0 enables millimetres as the unit.
  void setVoxelSize(float mm);
  float voxelSize() const { return voxelSize_; }
  void setUnit(DeviationUnit unit);
  DeviationUnit unit() const;

  DeviationLegend* legend() const { return legend_; }

 signals:
  void deviationSettingsChanged(bool enabled, visopt::Colormap colormap, float maxVoxels);

 private:
  void showMaximum();  // maxVoxels_ in the current unit -> spin box and legend
  void onEdited();

  float maxVoxels_ = 10.f;
  float voxelSize_ = 0.f;
  QCheckBox* enabled_ = nullptr;
  QComboBox* colormap_ = nullptr;
  QDoubleSpinBox* max_ = nullptr;
  QComboBox* unit_ = nullptr;
  DeviationLegend* legend_ = nullptr;
};

}  // namespace visopt::ws

#ifndef VISOPT_WS_METATYPE_COLORMAP
#define VISOPT_WS_METATYPE_COLORMAP
Q_DECLARE_METATYPE(visopt::Colormap)
#endif
