#pragma once
/// \file
/// \brief The bytes a frame parser has received and not yet consumed (MAVLink, UBX): appended
/// at the back, consumed from the front, compacted once half of it is consumed.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace skylane::link {

struct ByteWindow {
  std::vector<std::uint8_t> bytes;
  std::size_t start = 0;  ///< the first byte not consumed

  void push(const std::uint8_t* data, std::size_t n) {
    if (start > 0 && start >= bytes.size() / 2) {
      bytes.erase(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(start));
      start = 0;
    }
    bytes.insert(bytes.end(), data, data + n);
  }
  void drop(std::size_t n) { start = std::min(bytes.size(), start + n); }
  [[nodiscard]] std::size_t pending() const { return bytes.size() - start; }
};

}  // namespace skylane::link
