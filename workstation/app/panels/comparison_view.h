// Side-by-side comparison of N labelled renderings (Himmler & Günther 2026, Fig. 10: ours, maximum
// importance projection, cut-away, transparency modulation): one row for up to three, a 2x2 grid
// for four, a near-square grid beyond. Each image is scaled to fit its cell with its aspect ratio
// kept.
#pragma once

#include <utility>
#include <vector>

#include <QImage>
#include <QRect>
#include <QSize>
#include <QString>
#include <QWidget>

class QLabel;
class QProgressBar;
class QPushButton;

namespace visopt::ws {

// Columns (width) and rows (height) of the grid for n images.
QSize comparisonGridShape(int n);
// The largest rectangle of `image`'s aspect ratio inside `cell`, centred; empty for an empty
// image or cell.
QRect fitKeepingAspect(const QSize& image, const QRect& cell);

class ComparisonView : public QWidget {
  Q_OBJECT
 public:
  explicit ComparisonView(QWidget* parent = nullptr);

  void setImages(const std::vector<std::pair<QString, QImage>>& images);
  const std::vector<std::pair<QString, QImage>>& images() const { return images_; }
  bool isBusy() const { return busy_; }

  // Where image i is drawn, in this widget's coordinates (empty when out of range).
  QRect imageRect(int i) const;
  // The grid at the images' own resolution (each cell as large as the largest image) with the
  // labels above the images: what "Save as PNG…" should write.
  QImage composite() const;

 public slots:
  // Shows an indeterminate progress bar and disables saving while true.
  void setBusy(bool busy);

 signals:
  void saveRequested();

 private:
  void updateControls();

  std::vector<std::pair<QString, QImage>> images_;
  bool busy_ = false;
  QWidget* canvas_ = nullptr;
  QProgressBar* progress_ = nullptr;
  QPushButton* save_ = nullptr;
};

}  // namespace visopt::ws
