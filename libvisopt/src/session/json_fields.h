// Inviwo-style serialisation of plain settings structs: one table of (key, member) per struct
// drives both directions; writing keeps only members that differ from a default-constructed
// struct, reading starts from the defaults and overrides what the JSON holds.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "session/json_read.h"

namespace visopt::session {

template <class S>
class FieldTable {
 public:
  using Member = std::variant<float S::*, int S::*, bool S::*, uint32_t S::*, glm::vec3 S::*>;

  FieldTable& add(const char* key, Member member) {
    fields_.emplace_back(key, member);
    return *this;
  }

  // Only the members that differ from S{} (or from `defaults`).
  OrderedJson write(const S& value, const S& defaults = S{}) const {
    OrderedJson out = OrderedJson::object();
    // Named pair members, not a structured binding: clang 14 (the fuzzing build) cannot capture
    // a binding in a lambda.
    for (const auto& field : fields_)
      std::visit(
          [&](auto m) {
            if (!(value.*m == defaults.*m)) out[field.first] = toJson(value.*m);
          },
          field.second);
    return out;
  }

  // Every member (for values whose defaults mean nothing, like a camera).
  OrderedJson writeAll(const S& value) const {
    OrderedJson out = OrderedJson::object();
    for (const auto& field : fields_)
      std::visit([&](auto m) { out[field.first] = toJson(value.*m); }, field.second);
    return out;
  }

  // Members named in `j` override those of `out`; unknown keys are ignored (a newer minor
  // addition), wrongly typed values throw BadInput naming `where`.
  void read(const nlohmann::json& j, S& out, const Where& where) const {
    expectObject(j, where);
    for (const auto& field : fields_) {
      auto it = j.find(field.first);
      if (it == j.end()) continue;
      std::visit([&](auto m) { readValue(*it, out.*m, where.key(field.first)); }, field.second);
    }
  }

 private:
  std::vector<std::pair<const char*, Member>> fields_;
};

}  // namespace visopt::session
