#pragma once
// `InternedLists`: lists of small unsigned values, each interned as one number, so that a memo
// key holds a whole list in one word (BacktrackingSuccess's restore values, the starts of
// ConcurrentContiguousSuccess's give-up term).
//
// List 0 is empty; list i > 0 is list parent(i) followed by last(i). Appending a value to a list
// gives the same number every time; numbers are given in order of first appearance, so the same
// sequence of appends numbers the lists the same way on every run.
//
// Cost: append is one hash-table lookup (two vector pushes the first time); prefix walks one
// parent per value it drops. Memory: 4 + sizeof(Value) bytes and a hash-table slot per list.

#include <absl/container/flat_hash_map.h>

#include <cstdint>
#include <type_traits>
#include <vector>

namespace ontime {

template <class Value>
class InternedLists {
  static_assert(std::is_unsigned_v<Value> && sizeof(Value) <= 4, "values of at most 32 bits");

 public:
  // The empty list.
  static constexpr std::uint32_t kEmpty = 0;

  // The list `list` followed by `value`.
  std::uint32_t append(std::uint32_t list, Value value) {
    const std::uint64_t edge = (std::uint64_t{list} << 32U) | value;
    const auto [child, added] = children_.try_emplace(edge, static_cast<std::uint32_t>(parents_.size()));
    if (added) {
      parents_.push_back(list);
      values_.push_back(value);
    }
    return child->second;
  }
  // The list of the first `count` values of `list`, a list of `length` values (count <= length).
  std::uint32_t prefix(std::uint32_t list, int length, int count) const {
    for (; length > count; --length) list = parents_[list];
    return list;
  }
  // The value at `position` (from 0) of `list`, a list of more than `position` of `length` values.
  Value at(std::uint32_t list, int length, int position) const { return values_[prefix(list, length, position + 1)]; }

 private:
  std::vector<std::uint32_t> parents_{kEmpty};
  std::vector<Value> values_{0};
  absl::flat_hash_map<std::uint64_t, std::uint32_t> children_;
};

}  // namespace ontime
