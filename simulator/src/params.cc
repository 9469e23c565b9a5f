#include "arflex_sim/params.h"

#include <cmath>

namespace arflex {
namespace sim {
namespace {

// splitmix64: a tiny, well-documented 64-bit generator (Steele, Lea, Flood 2014).
class SplitMix64 {
 public:
  explicit SplitMix64(uint64_t seed) : state_(seed) {}
  uint64_t Next() {
    uint64_t z = (state_ += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
  }
  // Uniform in (0, 1): 53 random bits, never 0.
  double Uniform() { return (static_cast<double>(Next() >> 11) + 0.5) * 0x1.0p-53; }
  // Standard normal by Box-Muller (cosine branch only, so the sequence is simple to
  // reproduce: two uniforms per draw).
  double Normal() {
    const double u1 = Uniform();
    const double u2 = Uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * 3.14159265358979323846 * u2);
  }
  double TruncatedNormal(double sigma, double clip) {
    for (;;) {
      const double x = Normal();
      if (std::fabs(x) <= clip) return sigma * x;
    }
  }

 private:
  uint64_t state_;
};

}  // namespace

ErrorSet DrawErrorSet(uint64_t seed, const ErrorModel& model) {
  ErrorSet errors;
  errors.seed = seed;
  SplitMix64 rng(seed);
  for (Vec3& e : errors.offset_error) {
    for (double& c : e) c = rng.TruncatedNormal(model.length_sigma, model.clip_sigma);
  }
  for (double& q : errors.joint_offset) {
    q = rng.TruncatedNormal(model.joint_offset_sigma, model.clip_sigma);
  }
  return errors;
}

ArmParams ApplyGeometryErrors(const ArmParams& arm, const ErrorSet& errors) {
  ArmParams out = arm;
  for (int i = 0; i < kNumJoints; ++i) {
    for (int k = 0; k < 3; ++k) out.links[i].offset[k] += errors.offset_error[i][k];
  }
  for (int k = 0; k < 3; ++k) out.tcp_offset[k] += errors.offset_error[kNumJoints][k];
  return out;
}

CellConfig DefaultCellConfig() {
  CellConfig config;
  config.cameras = cellmodel::DefaultCameras();
  config.tags = cellmodel::DefaultTags();
  return config;
}

}  // namespace sim
}  // namespace arflex
