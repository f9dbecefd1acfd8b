// The nmbake command's progress line on stderr: one line, rewritten in place, naming the stage
// that runs, with the time since the command started and, once tracing has run for a second, an
// estimate of the time it has left. A thread redraws it four times a second, so the time moves
// while a long stage (a BVH of millions of triangles) gives no news of its own.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <functional>
#include <mutex>
#include <string>
#include <thread>

namespace nmbake {

// The line's text: "nmbake: tracing  42% [########............] 3.1 s, about 4.2 s left", or
// "nmbake: building the BVH, 1.2 s" for a stage without a fraction (fraction < 0). `elapsed` is
// the time since the command started, `stage_elapsed` the time in this stage; the time left is
// given for a stage with a fraction after its first second: stage_elapsed * (1 - f) / f.
std::string progress_text(const std::string& stage, double fraction, double elapsed, double stage_elapsed);

class Progress {
 public:
  using Clock = std::chrono::steady_clock;
  // Draws nothing unless `enabled`. `cancelled` is asked at each fraction (the bake's progress
  // callback stops the bake when it answers true).
  Progress(bool enabled, Clock::time_point start, std::function<bool()> cancelled);
  ~Progress();  // clears the line
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  // A new stage. With `tick` false the line is drawn once and not redrawn until the next stage:
  // the image writes, whose encoders' stderr is redirected for their duration (image_io.cpp).
  void stage(const char* name, bool tick = true);
  // The running stage's fraction done, 0-1; false once cancelled.
  bool fraction(double f);
  // Runs `print` (which writes whole lines to stderr) with the line cleared, then redraws it.
  void above(const std::function<void()>& print);
  // Clears the line and stops redrawing it, before the summary.
  void finish();
  // Clears the line until the next stage (a batch's job done, before its summary line).
  void hold();
  // Put before every stage's name from now on ("job 3 of 20: "; a batch's one line).
  void label(const std::string& text);

 private:
  void draw(Clock::time_point now);  // with mutex_ held
  void clear();                      // with mutex_ held
  void tick();

  const bool enabled_;
  const Clock::time_point start_;
  const std::function<bool()> cancelled_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::string stage_, label_;
  double fraction_ = -1.0;
  bool ticking_ = false, stopped_ = false;
  Clock::time_point stage_start_;
  std::size_t shown_ = 0;  // characters on the line now
  int last_percent_ = -1;
  std::thread ticker_;
};

}  // namespace nmbake
