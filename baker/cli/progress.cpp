#include "cli/progress.h"

#include <algorithm>
#include <cstdio>
#include <system_error>

namespace nmbake {
namespace {

// "3.1 s", "12 s", "2 min 5 s".
std::string duration_text(double seconds) {
  char text[32];
  if (seconds < 10.0) std::snprintf(text, sizeof text, "%.1f s", seconds);
  else if (seconds < 60.0) std::snprintf(text, sizeof text, "%.0f s", seconds);
  else std::snprintf(text, sizeof text, "%d min %d s", int(seconds / 60.0), int(seconds) % 60);
  return text;
}

constexpr int kBarWidth = 30;
constexpr auto kRedraw = std::chrono::milliseconds(250);

}  // namespace

std::string progress_text(const std::string& stage, double fraction, double elapsed, double stage_elapsed) {
  std::string text = "nmbake: " + stage;
  if (fraction < 0.0) return text + ", " + duration_text(elapsed);
  const double f = std::clamp(fraction, 0.0, 1.0);
  const int filled = int(f * kBarWidth);
  char percent[8];
  std::snprintf(percent, sizeof percent, " %3d%% ", int(f * 100.0));
  text += percent + ("[" + std::string(std::size_t(filled), '#') + std::string(std::size_t(kBarWidth - filled), '.') + "] ");
  text += duration_text(elapsed);
  if (stage_elapsed >= 1.0 && f > 0.0 && f < 1.0) text += ", about " + duration_text(stage_elapsed * (1.0 - f) / f) + " left";
  return text;
}

Progress::Progress(bool enabled, Clock::time_point start, std::function<bool()> cancelled)
    : enabled_(enabled), start_(start), cancelled_(std::move(cancelled)), stage_start_(start) {
  if (!enabled_) return;
  try {
    ticker_ = std::thread([this] { tick(); });
  } catch (const std::system_error&) {
    // No thread (ulimit): the line is drawn at each stage and fraction only.
  }
}

Progress::~Progress() { finish(); }

void Progress::stage(const char* name, bool tick) {
  if (!enabled_) return;
  std::lock_guard<std::mutex> lock(mutex_);
  if (stopped_) return;
  stage_ = label_ + name;
  fraction_ = -1.0;
  last_percent_ = -1;
  ticking_ = tick;
  stage_start_ = Clock::now();
  draw(stage_start_);
}

bool Progress::fraction(double f) {
  if (cancelled_ && cancelled_()) return false;
  if (!enabled_) return true;
  std::lock_guard<std::mutex> lock(mutex_);
  if (stopped_) return true;
  fraction_ = f;
  const int percent = int(std::clamp(f, 0.0, 1.0) * 100.0);
  if (percent != last_percent_) draw(Clock::now());
  last_percent_ = percent;
  return true;
}

void Progress::above(const std::function<void()>& print) {
  if (!enabled_) return print();
  std::lock_guard<std::mutex> lock(mutex_);
  clear();
  print();
  std::fflush(stderr);
  if (!stopped_ && !stage_.empty()) draw(Clock::now());
}

void Progress::finish() {
  if (!enabled_) return;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!stopped_) clear();
    stopped_ = true;
  }
  wake_.notify_all();
  if (ticker_.joinable()) ticker_.join();
}

void Progress::hold() {
  if (!enabled_) return;
  std::lock_guard<std::mutex> lock(mutex_);
  if (stopped_) return;
  clear();
  stage_.clear();
  ticking_ = false;
}

void Progress::label(const std::string& text) {
  std::lock_guard<std::mutex> lock(mutex_);
  label_ = text;
}

void Progress::draw(Clock::time_point now) {
  const std::string text = progress_text(stage_, fraction_, std::chrono::duration<double>(now - start_).count(),
                                         std::chrono::duration<double>(now - stage_start_).count());
  // Spaces over what a longer line left, then back to the line's end.
  const std::size_t pad = shown_ > text.size() ? shown_ - text.size() : 0;
  std::fprintf(stderr, "\r%s%*s", text.c_str(), int(pad), "");
  if (pad) std::fprintf(stderr, "\r%s", text.c_str());
  std::fflush(stderr);
  shown_ = text.size();
}

void Progress::clear() {
  if (!shown_) return;
  std::fprintf(stderr, "\r%*s\r", int(shown_), "");
  std::fflush(stderr);
  shown_ = 0;
}

void Progress::tick() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (!stopped_) {
    wake_.wait_for(lock, kRedraw);
    if (!stopped_ && ticking_ && !stage_.empty()) draw(Clock::now());
  }
}

}  // namespace nmbake
