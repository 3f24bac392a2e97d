#include "driftlab/nav_state.h"

namespace driftlab {

NavError ComputeNavError(const NavEnvironment& env, const NavState& estimate,
                         const NavState& truth) {
  NavError e;
  e.r_ned_m = env.PositionErrorNed(estimate.llh, truth.llh);
  e.v_ned_m_per_s = estimate.v_eb_n - truth.v_eb_n;
  e.euler_rad = EulerDifference(estimate.euler(), truth.euler());
  e.psi_nb_n_rad = AttitudeErrorNed(estimate.C_b_n(), truth.C_b_n());
  return e;
}

}  // namespace driftlab
