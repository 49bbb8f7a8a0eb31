// The screen-space windowing mask (Himmler & Günther 2026, §III-F, Fig. 8): the user paints, over
// the image, where the importance along the view rays is masked, so the context in front of the
// important structures is kept there as a depth cue.
//
// The tool holds a coverage raster c in [0, 1] (rasterWidth x rasterHeight over the whole image,
// row 0 at the top) painted with a soft round brush: a drag raises coverage, a Ctrl-drag lowers
// it, a Shift-drag fills (Ctrl+Shift: empties) a rectangle. What it sends to the engine:
//   Semantics::PaintMasks (default): weights = 1 - c: painted pixels lose their importance.
//   Semantics::PaintKeeps:           weights = c: only painted pixels keep their importance.
// Nothing painted (c == 0 everywhere) means NO mask in both semantics: the tool emits
// windowMaskCleared() (-> Engine::clearScreenMask), never all-zero or all-one weights, since
// Engine::setScreenMask multiplies the importance by the weights.
#pragma once

#include <algorithm>
#include <optional>
#include <vector>

#include <QElapsedTimer>
#include <QPointF>
#include <QRectF>
#include <QSize>
#include <QTimer>

#include "viewport_tool.h"

namespace visopt::ws {

class WindowMaskTool : public ViewportTool {
  Q_OBJECT
 public:
  enum class Semantics { PaintMasks, PaintKeeps };

  explicit WindowMaskTool(QObject* parent = nullptr);

  // Resizes the raster (clears it; emits windowMaskCleared when something was painted).
  void setRasterSize(int width, int height);
  int rasterWidth() const { return width_; }
  int rasterHeight() const { return height_; }
  void setSemantics(Semantics semantics);
  Semantics semantics() const { return semantics_; }
  // Brush radius in widget pixels; softness: the fraction of the radius over which the brush
  // fades out (0: hard edge).
  void setBrushRadius(double pixels) { brushRadius_ = std::max(pixels, 0.5); }
  double brushRadius() const { return brushRadius_; }
  void setSoftness(double softness) { softness_ = std::clamp(softness, 0.0, 1.0); }

  // Coverage c per raster cell (row 0 at the top), and whether any cell is non-zero.
  const std::vector<float>& coverage() const { return coverage_; }
  bool empty() const;
  // The weights the engine gets (see Semantics); meaningful only when !empty().
  std::vector<float> weights() const;

  bool mousePress(QMouseEvent* event, const ViewContext& view) override;
  bool mouseMove(QMouseEvent* event, const ViewContext& view) override;
  bool mouseRelease(QMouseEvent* event, const ViewContext& view) override;
  bool keyPress(QKeyEvent* event, const ViewContext& view) override;
  void deactivate() override;  // cancels a stroke in progress
  void paintOverlay(QPainter& painter, const ViewContext& view) override;

  // Paints one dab of the soft brush at a widget position (add: raise coverage, else lower).
  void dab(QPointF widgetPos, QSize imageSize, bool add);
  // Fills (add) or empties the cells whose centres lie in a widget-space rectangle.
  void fillRect(QRectF widgetRect, QSize imageSize, bool add);

 public slots:
  void clear();
  void cancelStroke();

 signals:
  void windowMaskChanged(std::vector<float> weights, int width, int height);
  void windowMaskCleared();

 private:
  void segment(QPointF from, QPointF to, QSize imageSize, bool add);
  void publish();
  void liveUpdate();

  int width_ = 128, height_ = 128;
  Semantics semantics_ = Semantics::PaintMasks;
  double brushRadius_ = 24.0, softness_ = 0.5;
  std::vector<float> coverage_;

  enum class Drag { None, Brush, Rect } drag_ = Drag::None;
  bool adding_ = true;
  QPointF start_, last_;
  std::vector<float> before_;  // coverage at the press, for Escape
  bool wasEmpty_ = true;       // whether listeners last heard "no mask"
  std::optional<QPointF> cursor_;
  QElapsedTimer sinceEmit_;
  QTimer pending_;
  bool dirty_ = false;
};

}  // namespace visopt::ws
