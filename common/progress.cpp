#include "common/progress.h"

#include <unistd.h>

#include <cmath>
#include <cstdio>

namespace specimen {

TerminalProgress::TerminalProgress(bool quiet, bool lines)
    : enabled_(!quiet && (lines || isatty(STDERR_FILENO))),
      lines_(lines && !isatty(STDERR_FILENO)),
      start_(std::chrono::steady_clock::now()),
      last_draw_(start_ - std::chrono::seconds(1)) {}

TerminalProgress::~TerminalProgress() { Finish(); }

void TerminalProgress::Update(double fraction, const std::string& message) {
  if (!enabled_) return;
  const auto now = std::chrono::steady_clock::now();
  if (lines_) {
    if (std::abs(fraction - last_fraction_) < 0.02 && fraction < 1.0 && now - last_draw_ < std::chrono::seconds(10)) return;
    last_draw_ = now;
    last_fraction_ = fraction;
    const double elapsed = std::chrono::duration<double>(now - start_).count();
    if (fraction < 0) std::fprintf(stderr, "[%7.1f s] %s\n", elapsed, message.c_str());
    else std::fprintf(stderr, "[%7.1f s] %3.0f%%  %s\n", elapsed, 100.0 * fraction, message.c_str());
    std::fflush(stderr);
    return;
  }
  // At most ten redraws a second: drawing must never slow the work down.
  if (now - last_draw_ < std::chrono::milliseconds(100) && fraction < 1.0) return;
  last_draw_ = now;
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  char bar[24] = {0};
  const int width = 20;
  const int filled = fraction < 0 ? 0 : static_cast<int>(fraction * width + 0.5);
  for (int i = 0; i < width; ++i) bar[i] = i < filled ? '#' : '.';
  if (fraction < 0)
    std::fprintf(stderr, "\r\033[K[%6.1f s] %s", elapsed, message.c_str());
  else
    std::fprintf(stderr, "\r\033[K[%s] %3.0f%% %6.1f s  %s", bar, 100.0 * fraction, elapsed,
                 message.c_str());
  std::fflush(stderr);
  drawn_ = true;
}

void TerminalProgress::Finish() {
  if (enabled_ && drawn_ && !lines_) {
    std::fprintf(stderr, "\r\033[K");
    std::fflush(stderr);
  }
  drawn_ = false;
}

ProgressCallback TerminalProgress::Callback() {
  if (!enabled_) return nullptr;
  return [this](double fraction, const std::string& message) { Update(fraction, message); };
}

}  // namespace specimen
