#include "visopt/field.h"

#include <utility>

#include "core/field_view.h"
#include "exec/parallel.h"
#include "visopt/error.h"
#include "visopt/memory_ledger.h"

namespace visopt {

Field3D::Field3D(std::string name, const GridSpec& grid, Precision precision, MemoryLedger* ledger)
    : name_(std::move(name)), grid_(grid), precision_(precision), ledger_(ledger) {
  if (grid.dims.x <= 0 || grid.dims.y <= 0 || grid.dims.z <= 0)
    throw Error(ErrorKind::Usage, "field '" + name_ + "' needs positive dimensions");
  data_ = exec::allocate(bytes());
  if (ledger_) ledgerToken_ = ledger_->add(name_, bytes(), toString(precision_));
}

Field3D::~Field3D() {
  release();
}

void Field3D::release() {
  if (ledger_ && ledgerToken_) ledger_->remove(ledgerToken_);
  exec::deallocate(data_);
  data_ = nullptr;
  ledgerToken_ = 0;
}

Field3D::Field3D(Field3D&& o) noexcept
    : name_(std::move(o.name_)),
      grid_(o.grid_),
      precision_(o.precision_),
      data_(o.data_),
      ledger_(o.ledger_),
      ledgerToken_(o.ledgerToken_) {
  o.data_ = nullptr;
  o.ledgerToken_ = 0;
}

Field3D& Field3D::operator=(Field3D&& o) noexcept {
  if (this != &o) {
    release();
    name_ = std::move(o.name_);
    grid_ = o.grid_;
    precision_ = o.precision_;
    data_ = o.data_;
    ledger_ = o.ledger_;
    ledgerToken_ = o.ledgerToken_;
    o.data_ = nullptr;
    o.ledgerToken_ = 0;
  }
  return *this;
}

void Field3D::rename(std::string name, MemoryLedger* ledger) {
  if (ledger_ && ledgerToken_) ledger_->remove(ledgerToken_);
  name_ = std::move(name);
  ledger_ = ledger;
  ledgerToken_ = ledger_ && data_ ? ledger_->add(name_, bytes(), toString(precision_)) : 0;
}

float Field3D::get(size_t i) const {
  return FieldView(*this).load(i);
}
void Field3D::set(size_t i, float v) {
  FieldView(*this).store(i, v);
}

void Field3D::fill(float v) {
  FieldView view(*this);
  exec::parallelFor("fill", int64_t(size()), [=](int64_t i) { view.store(size_t(i), v); });
}

}  // namespace visopt
