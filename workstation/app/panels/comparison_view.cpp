#include "panels/comparison_view.h"

#include <algorithm>
#include <cmath>

#include <QFontMetrics>
#include <QHBoxLayout>
#include <QPainter>
#include <QProgressBar>
#include <QPushButton>
#include <QVBoxLayout>

namespace visopt::ws {

namespace {

constexpr int kMargin = 4;

// The cells of a grid of n images over `area`: label strip of `labelHeight` above each image.
struct Cell {
  QRect label, image;
};

std::vector<Cell> layoutCells(int n, const QRect& area, int labelHeight) {
  std::vector<Cell> cells;
  if (n <= 0) return cells;
  const QSize shape = comparisonGridShape(n);
  const int cols = shape.width(), rows = shape.height();
  const int cellW = std::max(1, (area.width() - kMargin * (cols + 1)) / cols);
  const int cellH = std::max(1, (area.height() - kMargin * (rows + 1)) / rows);
  for (int i = 0; i < n; ++i) {
    const int c = i % cols, r = i / cols;
    const int x = area.left() + kMargin + c * (cellW + kMargin);
    const int y = area.top() + kMargin + r * (cellH + kMargin);
    Cell cell;
    cell.label = QRect(x, y, cellW, labelHeight);
    cell.image = QRect(x, y + labelHeight, cellW, std::max(1, cellH - labelHeight));
    cells.push_back(cell);
  }
  return cells;
}

void paintGrid(QPainter& painter, const std::vector<std::pair<QString, QImage>>& images,
               const QRect& area, int labelHeight, const QColor& text) {
  const std::vector<Cell> cells = layoutCells(static_cast<int>(images.size()), area, labelHeight);
  painter.setRenderHint(QPainter::SmoothPixmapTransform, true);
  for (size_t i = 0; i < cells.size(); ++i) {
    painter.setPen(text);
    painter.drawText(cells[i].label, Qt::AlignHCenter | Qt::AlignVCenter, images[i].first);
    const QImage& image = images[i].second;
    const QRect target = fitKeepingAspect(image.size(), cells[i].image);
    if (!target.isEmpty()) painter.drawImage(target, image);
  }
}

// Paints the images of its ComparisonView.
class Canvas : public QWidget {
 public:
  Canvas(const std::vector<std::pair<QString, QImage>>& images, QWidget* parent)
      : QWidget(parent), images_(images) {
    setMinimumSize(160, 120);
    setSizePolicy(QSizePolicy::Expanding, QSizePolicy::Expanding);
  }
  int labelHeight() const { return fontMetrics().height() + 4; }
  QRect imageRect(int i) const {
    const std::vector<Cell> cells =
        layoutCells(static_cast<int>(images_.size()), rect(), labelHeight());
    if (i < 0 || i >= static_cast<int>(cells.size())) return {};
    return fitKeepingAspect(images_[static_cast<size_t>(i)].second.size(),
                            cells[static_cast<size_t>(i)].image);
  }

 protected:
  void paintEvent(QPaintEvent*) override {
    QPainter painter(this);
    painter.fillRect(rect(), palette().window());
    if (images_.empty()) {
      painter.setPen(palette().color(QPalette::PlaceholderText));
      painter.drawText(rect(), Qt::AlignCenter, tr("No comparison yet"));
      return;
    }
    paintGrid(painter, images_, rect(), labelHeight(), palette().color(QPalette::WindowText));
  }

 private:
  const std::vector<std::pair<QString, QImage>>& images_;
};

}  // namespace

QSize comparisonGridShape(int n) {
  if (n <= 0) return {0, 0};
  if (n <= 3) return {n, 1};
  const int cols = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(n))));
  return {cols, (n + cols - 1) / cols};
}

QRect fitKeepingAspect(const QSize& image, const QRect& cell) {
  if (image.isEmpty() || cell.isEmpty()) return {};
  const QSize scaled = image.scaled(cell.size(), Qt::KeepAspectRatio);
  return QRect(cell.left() + (cell.width() - scaled.width()) / 2,
               cell.top() + (cell.height() - scaled.height()) / 2, scaled.width(), scaled.height());
}

ComparisonView::ComparisonView(QWidget* parent) : QWidget(parent) {
  auto* layout = new QVBoxLayout(this);
  canvas_ = new Canvas(images_, this);
  canvas_->setObjectName(QStringLiteral("canvas"));
  layout->addWidget(canvas_, 1);

  auto* bottom = new QHBoxLayout;
  progress_ = new QProgressBar(this);
  progress_->setObjectName(QStringLiteral("busy"));
  progress_->setRange(0, 0);  // indeterminate
  progress_->setFormat(tr("Rendering…"));
  progress_->setTextVisible(true);
  progress_->setVisible(false);
  save_ = new QPushButton(tr("Save as PNG…"), this);
  save_->setObjectName(QStringLiteral("save"));
  save_->setToolTip(tr("Save the comparison grid, with its labels, as a PNG image."));
  bottom->addWidget(progress_, 1);
  bottom->addStretch(0);
  bottom->addWidget(save_);
  layout->addLayout(bottom);

  connect(save_, &QPushButton::clicked, this, &ComparisonView::saveRequested);
  updateControls();
}

void ComparisonView::setImages(const std::vector<std::pair<QString, QImage>>& images) {
  images_ = images;
  updateControls();
  canvas_->update();
}

void ComparisonView::setBusy(bool busy) {
  busy_ = busy;
  updateControls();
}

void ComparisonView::updateControls() {
  progress_->setVisible(busy_);
  save_->setEnabled(!busy_ && !images_.empty());
}

QRect ComparisonView::imageRect(int i) const {
  const QRect r = static_cast<const Canvas*>(canvas_)->imageRect(i);
  return r.isEmpty() ? r : r.translated(canvas_->pos());
}

QImage ComparisonView::composite() const {
  if (images_.empty()) return {};
  QSize cell(1, 1);
  for (const auto& [label, image] : images_) cell = cell.expandedTo(image.size());
  const QFontMetrics metrics(font());
  const int labelHeight = metrics.height() + 4;
  const QSize shape = comparisonGridShape(static_cast<int>(images_.size()));
  const int width = shape.width() * cell.width() + kMargin * (shape.width() + 1);
  const int height =
      shape.height() * (cell.height() + labelHeight) + kMargin * (shape.height() + 1);
  QImage out(width, height, QImage::Format_RGB32);
  out.fill(palette().color(QPalette::Window));
  QPainter painter(&out);
  painter.setFont(font());
  paintGrid(painter, images_, out.rect(), labelHeight, palette().color(QPalette::WindowText));
  return out;
}

}  // namespace visopt::ws
