#pragma once
/// \file
/// \brief A progress bar on stderr for long runs, drawn only when stderr is a terminal or forced.

#include <unistd.h>

#include <cstdio>
#include <string>
#include <utility>

namespace skylane::cli {

/// \brief Call with (done, total); redraws when the bar moves by a permille, ends the line at total.
class Progress {
 public:
  Progress(std::string what, bool force) : what_(std::move(what)), on_(force || isatty(STDERR_FILENO)) {}
  void operator()(std::size_t done, std::size_t total) {
    if (!on_ || total == 0) return;
    const int permille = static_cast<int>(1000 * done / total);
    if (permille == last_permille_ && done != total) return;  // redraw only when it moves
    last_permille_ = permille;
    const int width = 30;
    const int filled = static_cast<int>(width * done / total);
    std::fprintf(stderr, "\r%s [%.*s%*s] %zu/%zu", what_.c_str(), filled, "##############################",
                 width - filled, "", done, total);
    if (done == total) std::fprintf(stderr, "\n");
    std::fflush(stderr);
  }

 private:
  std::string what_;
  bool on_;
  int last_permille_ = -1;
};

}  // namespace skylane::cli
