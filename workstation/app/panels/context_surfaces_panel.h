// The context surfaces (Himmler & Günther 2026, §III): a list with visibility, colour and
// representation, and a dialog that states a new surface as a ContextSurfaceSpec (an isosurface of
// the data, a mesh file or a .vdb level set; filled or a thin shell). The panel changes nothing
// itself: it emits requests, and the engine's surfaces come back through setSurfaces.
#pragma once

#include <functional>
#include <optional>
#include <vector>

#include <QColor>
#include <QDialog>
#include <QMetaType>
#include <QString>
#include <QWidget>

#include <glm/glm.hpp>

#include <visopt/context_surface.h>

class QAction;
class QCheckBox;
class QComboBox;
class QDoubleSpinBox;
class QLabel;
class QLineEdit;
class QPushButton;
class QRadioButton;
class QSlider;
class QStackedWidget;
class QTableWidget;
class QToolButton;

namespace visopt::ws {

// Surface colours are linear RGB (the renderer works in linear light); the screen shows sRGB.
QColor displayColor(const glm::vec3& linear);  // sRGB-encoded, clamped to [0, 1]
glm::vec3 linearColor(const QColor& display);  // sRGB-decoded

// What the add dialog asks for.
struct SurfaceSourceFields {
  enum class Kind { Iso, Mesh, Vdb };
  Kind kind = Kind::Iso;
  double isoValue = 0.0;
  bool insideHigh = true;  // iso: values above isoValue are inside
  QString file;            // mesh (OBJ/PLY/OFF/STL) or .vdb
  bool filled = true;
  double shell = 1.0;  // thin shell: reaches this far each side, world units (mm)
};

// Empty when `fields` make a valid surface, else why not (no file, shell thickness <= 0).
QString validateSurfaceFields(const SurfaceSourceFields& fields);
// The spec of `fields`: source "iso:VALUE:inside-high|inside-low" (VALUE in the shortest form
// that reads back as the same double), "mesh:FILE" or "vdb:FILE"; shell = 0 when filled.
ContextSurfaceSpec makeSurfaceSpec(const SurfaceSourceFields& fields);
// The list's text for a spec: "iso 0.35 (inside high)", "mesh: bunny.obj", "vdb: smoke.vdb".
QString describeSurfaceSource(const std::string& source);
// "filled" or "shell ±1.5 mm".
QString describeRepresentation(const ContextSurfaceSpec& spec);

// The dialog of "Add…". Tests drive it through setFields / the widgets and read spec() without
// exec().
class AddSurfaceDialog : public QDialog {
  Q_OBJECT
 public:
  explicit AddSurfaceDialog(QWidget* parent = nullptr);

  // The data's value range for the isovalue slider and spin box (the value is clamped into it).
  void setValueRange(double min, double max);
  void setKind(SurfaceSourceFields::Kind kind);
  void setFields(const SurfaceSourceFields& fields);
  SurfaceSourceFields fields() const;
  ContextSurfaceSpec spec() const { return makeSurfaceSpec(fields()); }
  bool isValid() const { return validateSurfaceFields(fields()).isEmpty(); }

 private:
  void updateState();
  void browse();
  int sliderPosition(double value) const;

  double min_ = 0.0, max_ = 1.0;
  QComboBox* kind_ = nullptr;
  QStackedWidget* pages_ = nullptr;
  QSlider* isoSlider_ = nullptr;
  QDoubleSpinBox* isoValue_ = nullptr;
  QComboBox* side_ = nullptr;
  QLineEdit* file_ = nullptr;
  QPushButton* browse_ = nullptr;
  QRadioButton* filled_ = nullptr;
  QRadioButton* shell_ = nullptr;
  QDoubleSpinBox* thickness_ = nullptr;
  QPushButton* ok_ = nullptr;
  QLabel* problem_ = nullptr;
};

class ContextSurfacesPanel : public QWidget {
  Q_OBJECT
 public:
  // Returns the chosen colour, or nullopt when cancelled. Default: QColorDialog::getColor.
  using ColorPicker = std::function<std::optional<QColor>(const QColor& initial, QWidget* parent)>;
  // Shows the add dialog; returns true when accepted. Default: dialog.exec() == Accepted.
  using DialogRunner = std::function<bool(AddSurfaceDialog& dialog)>;

  explicit ContextSurfacesPanel(QWidget* parent = nullptr);

  void setColorPicker(ColorPicker picker) { colorPicker_ = std::move(picker); }
  void setDialogRunner(DialogRunner runner) { dialogRunner_ = std::move(runner); }

  // The data's value range offered for isosurfaces.
  void setValueRange(double min, double max);
  const std::vector<ContextSurfaceSpec>& surfaces() const { return surfaces_; }
  int rowCount() const { return static_cast<int>(surfaces_.size()); }
  // The row's widgets (nullptr when out of range).
  QCheckBox* visibilityBox(int row) const;
  QToolButton* colorButton(int row) const;
  QTableWidget* table() const { return table_; }

 public slots:
  // Refreshes the list from the engine; emits nothing.
  void setSurfaces(const std::vector<visopt::ContextSurfaceSpec>& surfaces);
  // Opens the add dialog for `kind` and emits addSurfaceRequested when it is accepted.
  void requestAdd(visopt::ws::SurfaceSourceFields::Kind kind);
  // Opens the colour picker for `row` and emits colorChanged when a colour was chosen.
  void pickColor(int row);
  // Emits removeSurfaceRequested for the selected row, if any.
  void removeSelected();

 signals:
  void addSurfaceRequested(const visopt::ContextSurfaceSpec& spec);
  void removeSurfaceRequested(int row);
  void visibilityChanged(int row, bool visible);
  void colorChanged(int row, glm::vec3 color);

 private:
  void fillRow(int row);
  void updateButtons();

  std::vector<ContextSurfaceSpec> surfaces_;
  double min_ = 0.0, max_ = 1.0;
  ColorPicker colorPicker_;
  DialogRunner dialogRunner_;
  QTableWidget* table_ = nullptr;
  QToolButton* add_ = nullptr;
  QPushButton* remove_ = nullptr;
};

}  // namespace visopt::ws

// Guarded so that other workstation headers can declare the same library types.
#ifndef VISOPT_WS_METATYPE_CONTEXT_SURFACE_SPEC
#define VISOPT_WS_METATYPE_CONTEXT_SURFACE_SPEC
Q_DECLARE_METATYPE(visopt::ContextSurfaceSpec)
#endif
#ifndef VISOPT_WS_METATYPE_GLM_VEC3
#define VISOPT_WS_METATYPE_GLM_VEC3
Q_DECLARE_METATYPE(glm::vec3)
#endif
