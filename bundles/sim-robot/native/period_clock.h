// period_clock.h - how many periods of the world a cycle of sim-robot stands for (D77).
//
// The world a simulator stands for does not stop while the host does not run its RT half (a
// stall of the machine): a real arm's servo goes on, and the motion sources, other processes,
// go on moving the reference. PeriodClock keeps the time up to which the world is simulated and
// says, at each cycle, how many whole periods lie between it and now: 1 on time, k after a stall
// of k - 1 periods. The clock of the cycle's start is used, not its release time: rt-core runs
// the first cycle after a stall with the release it overslept (the reference read then is
// already k periods on), and skips the missed releases only after it.
//
// A cycle steps at most max_periods (no unbounded physics in one cycle); beyond that the world
// loses the rest, counted in lost(). No allocation, RT safe.
#ifndef SIM_ROBOT_PERIOD_CLOCK_H
#define SIM_ROBOT_PERIOD_CLOCK_H

#include <cstdint>

class PeriodClock {
 public:
  explicit PeriodClock(int max_periods) : max_(max_periods < 1 ? 1 : max_periods) {}

  // The next run starts afresh: its first cycle stands for one period (the time between two
  // runs, or a safe episode's own cycles, are not caught up).
  void Restart() { sim_ns_ = 0; }

  // The periods the cycle starting at @now_ns stands for: at least 1, at most max_periods.
  int Periods(uint64_t now_ns, uint64_t period_ns) {
    if (sim_ns_ == 0 || period_ns == 0) {
      sim_ns_ = now_ns;
      return 1;
    }
    uint64_t k = now_ns > sim_ns_ ? (now_ns - sim_ns_) / period_ns : 0;
    if (k < 1) k = 1;  // on the grid a cycle is a period after the one before: never ahead for long
    sim_ns_ += k * period_ns;
    if (k > static_cast<uint64_t>(max_)) {
      lost_ += k - static_cast<uint64_t>(max_);
      k = static_cast<uint64_t>(max_);
    }
    return static_cast<int>(k);
  }

  // Periods elapsed that were not simulated (stalls longer than max_periods).
  uint64_t lost() const { return lost_; }

 private:
  int max_;
  uint64_t sim_ns_ = 0;
  uint64_t lost_ = 0;
};

#endif  // SIM_ROBOT_PERIOD_CLOCK_H
