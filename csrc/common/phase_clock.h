// Wall time of the core's phases (preparing the scene; planning a pass: binning the scene
// into tiles, the backward pass's boundary pieces; the passes' per-pixel and per-boundary-
// sample work), summed over calls until read: benchmarks use
// it to say where an iteration's time goes (vecfit._core.phase_seconds()). Two clock reads
// per phase and call; host code only.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>

namespace vf {

enum Phase { PHASE_PREPARE, PHASE_PLAN, PHASE_FORWARD, PHASE_BACKWARD_INTERIOR, PHASE_BACKWARD_BOUNDARY, PHASE_COUNT };

inline const char* phase_name(int p) {
    static const char* names[PHASE_COUNT] = {"prepare", "plan", "forward", "backward interior", "backward boundary"};
    return names[p];
}

inline std::atomic<int64_t>* phase_nanoseconds() {
    static std::atomic<int64_t> ns[PHASE_COUNT] = {};
    return ns;
}

// Adds the time from its construction to its destruction to one phase.
class PhaseTimer {
  public:
    explicit PhaseTimer(Phase p) : phase_(p), start_(std::chrono::steady_clock::now()) {}
    ~PhaseTimer() {
        auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - start_);
        phase_nanoseconds()[phase_].fetch_add(ns.count(), std::memory_order_relaxed);
    }
    PhaseTimer(const PhaseTimer&) = delete;
    PhaseTimer& operator=(const PhaseTimer&) = delete;

  private:
    Phase phase_;
    std::chrono::steady_clock::time_point start_;
};

}  // namespace vf
