// The layers' storage on disk, one rank's: the scratch files of each layer (its keys, its
// outcomes' codes and the extras of the outcomes a tolerance touched) in the rank's private
// scratch directory, written by the forward pass, read back by the backward pass and removed as
// soon as it is done with them, with the disk they hold counted against the disk cap.

#include "solve/layered/storage.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "ontime/util/error.hpp"
#include "solve/layered/search.hpp"

namespace ontime::layered {

ScratchFile::ScratchFile(std::filesystem::path path, int layer, const char* mode)
    : path_(std::move(path)), layer_(layer), file_(std::fopen(path_.c_str(), mode)) {
  if (file_ == nullptr) fail("cannot open");
}

ScratchFile::~ScratchFile() {
  if (file_ != nullptr) std::fclose(file_);
}

void ScratchFile::close() {
  const bool failed = std::fclose(file_) != 0;
  file_ = nullptr;
  if (failed) fail("cannot write to");
}

void ScratchFile::fail(const char* what) const {
  throw ResourceLimitError("layer " + std::to_string(layer_) + ": " + what + " the scratch file " + path_.string() +
                           " (disk full?); free space or set --scratch");
}

template <std::size_t W>
void LayeredSearch<W>::write_keys(int t, const std::vector<Key>& keys) {
  ScratchFile file(scratch_.file(t, "keys"), t, "wb");
  file.write(keys.data(), keys.size());
  file.close();
  disk_bytes_ += keys.size() * sizeof(Key);
  solution_.peak_disk_bytes = std::max(solution_.peak_disk_bytes, disk_bytes_);
}

template <std::size_t W>
std::vector<PackedState<W>> LayeredSearch<W>::read_keys(int t, std::size_t count) {
  std::vector<Key> data(count);
  ScratchFile file(scratch_.file(t, "keys"), t, "rb");
  file.read(data.data(), count);
  return data;
}

template <std::size_t W>
void LayeredSearch<W>::remove_layer_files(int t) {
  for (const char* what : {"keys", "codes", "extras"}) {
    std::error_code error;
    const std::filesystem::path path = scratch_.file(t, what);
    const auto bytes = std::filesystem::file_size(path, error);
    if (!error) disk_bytes_ -= std::min<std::uint64_t>(disk_bytes_, bytes);
    std::filesystem::remove(path, error);
  }
}

// The members defined here, for every key width search_layers dispatches to (search.hpp).
#define ONTIME_INSTANTIATE_STORAGE(W)                                                      \
  template void LayeredSearch<(W)>::write_keys(int, const std::vector<PackedState<(W)>>&); \
  template std::vector<PackedState<(W)>> LayeredSearch<(W)>::read_keys(int, std::size_t);  \
  template void LayeredSearch<(W)>::remove_layer_files(int);
ONTIME_LAYERED_KEY_WIDTHS(ONTIME_INSTANTIATE_STORAGE)
#undef ONTIME_INSTANTIATE_STORAGE

}  // namespace ontime::layered
