#include "driftlab/nav_state.h"

namespace driftlab {

NavErrorTruth::NavErrorTruth(const NavEnvironment& env, const NavState& truth)
    : llh(truth.llh),
      v_eb_n(truth.v_eb_n),
      position_scale(env.PositionScaleAt(truth.llh)),
      euler(truth.euler()),
      C_b_n(truth.C_b_n()) {}

NavError ComputeNavError(const NavEnvironment& env, const NavState& estimate,
                         const NavState& truth) {
  return ComputeNavError(env, estimate, NavErrorTruth(env, truth));
}

NavError ComputeNavError(const NavEnvironment& env, const NavState& estimate,
                         const NavErrorTruth& truth) {
  NavError e;
  e.r_ned_m = env.PositionErrorNed(estimate.llh, truth.llh, truth.position_scale);
  e.v_ned_m_per_s = estimate.v_eb_n - truth.v_eb_n;
  const Matrix3d C_b_n = estimate.C_b_n();  // once for both (NavState::euler() is DcmToEuler of it)
  e.euler_rad = EulerDifference(DcmToEuler(C_b_n), truth.euler);
  e.psi_nb_n_rad = AttitudeErrorNed(C_b_n, truth.C_b_n);
  return e;
}

}  // namespace driftlab
