#pragma once

// Lanes: a few doubles side by side, for rollouts computed together (the paper model's sweeps
// and the extended servo model's fit roll out many recordings at once). Internal: shared by
// leglab::model and leglab::servo, not an API (it may change with any release).

#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

namespace leglab {

/// kLaneCount doubles in one vector of GCC's and Clang's vector extension: +, -, * and / act
/// lane by lane with the scalar operations' IEEE rounding, so a lane computes exactly what the
/// same expression on a double does, provided nothing is contracted into a fused multiply-add:
/// leglab_model compiles with -ffp-contract=off (model/CMakeLists.txt), and neither the
/// baseline nor the avx2 target has FMA anyway. Four lanes: one AVX register, or two SSE2
/// registers on the x86-64 baseline. Aligned to their size whatever the target (GCC would align
/// them to 16 bytes without AVX, where code compiled for AVX assumes 32).
inline constexpr size_t kLaneCount = 4;
inline constexpr size_t kLaneBytes = kLaneCount * sizeof(double);
static_assert(kLaneCount == 4, "Splat lists the lanes one by one");
using Lanes = double __attribute__((vector_size(kLaneBytes), aligned(kLaneBytes)));
/// A lane's bits; as a mask, each lane all ones (true) or all zeros (false), as comparisons of
/// Lanes give.
using LaneMask = int64_t __attribute__((vector_size(kLaneBytes), aligned(kLaneBytes)));
/// A lane's bits, unsigned (for shifts).
using LaneBits = uint64_t __attribute__((vector_size(kLaneBytes), aligned(kLaneBytes)));

// A vector of 32 bytes is passed to a call differently with AVX than without, so a function on
// Lanes called from code built for AVX2 must be inlined into it, whatever the optimisation
// (flatten does not inline at -O0): every one here, and every one taking or returning Lanes
// elsewhere, is always_inline. GCC's -Wpsabi warns of that difference where such a function
// is defined (turned off here and in sine_of_degrees.h for whoever includes them) and notes it
// where one is instantiated (-Wno-psabi on the targets that use Lanes); no call passes one.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"

// __builtin_bit_cast, not std::bit_cast: the latter is a function call unless inlined.
[[gnu::always_inline]] inline LaneMask Bits(Lanes x) { return __builtin_bit_cast(LaneMask, x); }
[[gnu::always_inline]] inline Lanes FromBits(LaneMask bits) {
  return __builtin_bit_cast(Lanes, bits);
}
inline constexpr int64_t kSignBit = std::numeric_limits<int64_t>::min();

/// Every lane `x` (-0 too).
[[gnu::always_inline]] inline Lanes Splat(double x) { return Lanes{x, x, x, x}; }

/// Each lane's `yes` where `mask` is true, else its `no`: bit operations, no branch.
[[gnu::always_inline]] inline Lanes Select(LaneMask mask, Lanes yes, Lanes no) {
  return FromBits((mask & Bits(yes)) | (~mask & Bits(no)));
}

/// std::abs and std::copysign, lane by lane.
[[gnu::always_inline]] inline Lanes Abs(Lanes x) { return FromBits(Bits(x) & ~kSignBit); }
[[gnu::always_inline]] inline Lanes CopySign(Lanes magnitude, Lanes sign) {
  return FromBits((Bits(magnitude) & ~kSignBit) | (Bits(sign) & kSignBit));
}

/// Whether every lane of `mask` is true (a branch per lane).
[[gnu::always_inline]] inline bool AllLanes(LaneMask mask) {
  bool all = true;
  for (size_t i = 0; i < kLaneCount; ++i) all = all && mask[i] != 0;
  return all;
}

#pragma GCC diagnostic pop

/// The instructions code on Lanes runs on: the x86-64 baseline (SSE2) or AVX2 (the same
/// arithmetic on wider registers, so the same bits). Code built for both picks one per call.
enum class LaneInstructions { kBaseline, kAvx2 };

/// The widest this processor runs.
inline LaneInstructions BestLaneInstructions() {
  static const LaneInstructions best =
      __builtin_cpu_supports("avx2") ? LaneInstructions::kAvx2 : LaneInstructions::kBaseline;
  return best;
}

/// Every instruction set this processor runs (the baseline, then AVX2 if it has it).
inline std::vector<LaneInstructions> AvailableLaneInstructions() {
  if (BestLaneInstructions() == LaneInstructions::kAvx2) {
    return {LaneInstructions::kBaseline, LaneInstructions::kAvx2};
  }
  return {LaneInstructions::kBaseline};
}

}  // namespace leglab
