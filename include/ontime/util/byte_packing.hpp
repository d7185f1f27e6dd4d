#pragma once
// Packing of plain values into bytes and back, for the results ranks exchange (ranks.hpp).
// Written here rather than taken from a serialization library because what travels is a few
// numbers, strings and arrays of plain structs between processes of one build (the same `ontime`
// binary on every rank), read back in the order written: the bytes of each value, as they are in
// memory, are all it needs, and the core stays free of a dependency for it.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

namespace ontime {

class BytePacker {
 public:
  // Appends the bytes of `value` as they are in memory.
  template <class T>
  void put(const T& value) {
    static_assert(std::is_trivially_copyable_v<T>);
    bytes_.append(reinterpret_cast<const char*>(&value), sizeof(T));
  }
  // Appends the length of `text` (8 bytes) and its characters.
  void put_string(std::string_view text) {
    put<std::uint64_t>(text.size());
    bytes_.append(text);
  }
  // Appends the number of values (8 bytes) and their bytes as they are in memory.
  template <class T>
  void put_vector(const std::vector<T>& values) {
    static_assert(std::is_trivially_copyable_v<T>);
    put<std::uint64_t>(values.size());
    bytes_.append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
  }
  // The bytes written so far.
  const std::string& bytes() const noexcept { return bytes_; }
  // The bytes written, moved out of the packer.
  std::string take() noexcept { return std::move(bytes_); }

 private:
  std::string bytes_;
};

// Reads what a BytePacker wrote, in the same order; std::runtime_error when the bytes run out
// (which only a bug can cause: the packer and the reader are one build).
class ByteUnpacker {
 public:
  // Reads `bytes`, which must outlive the unpacker.
  explicit ByteUnpacker(std::string_view bytes) noexcept : bytes_(bytes) {}
  // The next value, written by put<T>.
  template <class T>
  T get() {
    static_assert(std::is_trivially_copyable_v<T>);
    T value{};
    std::memcpy(&value, take(sizeof(T)), sizeof(T));
    return value;
  }
  // The next string, written by put_string.
  std::string get_string() {
    const auto size = get<std::uint64_t>();
    const char* data = take(size);
    return std::string(data, size);
  }
  // The next vector, written by put_vector<T>.
  template <class T>
  std::vector<T> get_vector() {
    static_assert(std::is_trivially_copyable_v<T>);
    const auto size = get<std::uint64_t>();
    if (size > bytes_.size() / std::max<std::size_t>(sizeof(T), 1)) fail();
    std::vector<T> values(size);
    if (size > 0) std::memcpy(values.data(), take(size * sizeof(T)), size * sizeof(T));
    return values;
  }
  // Whether every byte has been read.
  bool done() const noexcept { return bytes_.empty(); }

 private:
  const char* take(std::size_t size) {
    if (size > bytes_.size()) fail();
    const char* data = bytes_.data();
    bytes_.remove_prefix(size);
    return data;
  }
  [[noreturn]] static void fail() { throw std::runtime_error("results exchanged between ranks ended early"); }
  std::string_view bytes_;
};

}  // namespace ontime
