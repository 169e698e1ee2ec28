#pragma once

#include "leglab/model/identification.h"
#include "leglab/model/joint_model.h"

namespace leglab {

/// How EstimateJointModelInWindow searches.
struct WindowEstimationOptions {
  /// l and a are searched exhaustively over the current estimate's +-radius (within `bounds`),
  /// so a sliding estimate moves at most this far per update and costs (2r + 1)^2 fits
  /// instead of the whole grid.
  int lag_radius_ticks = 2;
  int accel_radius_ticks = 2;
  /// Hysteresis: l and a move only when the best neighbour's RMS residual is below (1 -
  /// switch_margin) times the best fit at the current l and a. On a walk's smooth requests
  /// neighbouring (l, a) with about the same l + a/2 fit almost equally well, and without it
  /// the estimate hops between them with the noise.
  double switch_margin = 0.05;
  /// The ranges l and a never leave (the identification's search ranges).
  IdentificationOptions bounds;
  /// v_max is taken as identified only when the fitted model saturates (|R(t-i) - M(t-1)| >=
  /// theta_0 for one of the requests that act at t) on at least this many ticks of the
  /// window; below it the data determine only the slope v_max / theta_0 of f.
  int min_saturated_ticks = 6;
};

/// The estimate of one window and what the data could say.
struct WindowEstimate {
  IdentificationResult fit;       ///< params and RMS open-loop prediction residual, deg
  bool v_max_identified = false;  ///< the window saturated the joint (see the options)
  int saturated_ticks = 0;        ///< ticks on which the fitted model saturates
};

/// Re-estimates a joint's model {v_max, theta_0, l, a} from one recorded window of applied
/// requests and measured angles (consecutive ticks, e.g. the latest steps of a walk): the
/// identification's own fit (IdentifyJointModel: open-loop prediction error, l and a
/// exhaustively, v_max and theta_0 by Nelder-Mead) restricted to l and a within the radii of
/// `current`, keeping current's l and a unless a neighbour fits clearly better
/// (switch_margin). When the window never drives the joint into saturation, v_max is not
/// identifiable (eq. 2 is then the line f(x) = (v_max / theta_0) x); the estimate keeps
/// current.v_max_deg_per_tick and sets theta_0 to keep the fitted slope.
/// Throws what IdentifyJointModel throws (std::invalid_argument on a window too short for
/// the searched l + a, a non-finite sample, or a joint that never moved) and
/// std::invalid_argument for an invalid `current`.
WindowEstimate EstimateJointModelInWindow(const JointRecording& window,
                                          const JointModelParams& current,
                                          const WindowEstimationOptions& options = {});

}  // namespace leglab
