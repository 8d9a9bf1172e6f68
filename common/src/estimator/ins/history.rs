//! The filter's stored past states. A delayed measurement (a GPS fix describes the aircraft
//! as it was some 100-200 ms before it arrives) is compared with the state of its own time,
//! and a correction moves the states stored after that time as it moved the present one, so
//! that the next delayed fix compares like with like.

use super::{Gain, Ins, Snapshot, HISTORY, IBG, IBO, IP, ITH, IV, MAX_VAR, MIN_VAR};
use crate::estimator::kalman::{clamp_diagonal, downdate};
use nalgebra::{UnitQuaternion, Vector3};

impl Ins {
    pub(super) fn remember(&mut self, t_us: u64) {
        // The stored states are kept in time order (searches stop early on it): a clock that
        // went back starts the history again.
        let newest = self.history.get(self.head).map(|s| s.t_us);
        if self.len > 0 && newest.is_some_and(|n| t_us <= n) {
            self.len = 0;
        }
        self.head = (self.head + 1) % HISTORY;
        if let Some(s) = self.history.get_mut(self.head) {
            *s = Snapshot {
                t_us,
                q: self.q,
                v: self.v,
                p: self.p,
            };
        }
        self.len = (self.len + 1).min(HISTORY);
    }

    /// The stored state closest to time `t_us` (the present state when nothing is stored).
    pub(super) fn state_at(&self, t_us: u64) -> Snapshot {
        let mut best = Snapshot {
            t_us,
            q: self.q,
            v: self.v,
            p: self.p,
        };
        let mut best_err = u64::MAX;
        // Newest first, in time order: once the distance grows it only grows.
        for k in 0..self.len {
            let i = (self.head + HISTORY - k) % HISTORY;
            if let Some(s) = self.history.get(i) {
                let e = s.t_us.abs_diff(t_us);
                if e < best_err {
                    best_err = e;
                    best = *s;
                } else if e > best_err {
                    break;
                }
            }
        }
        best
    }

    /// Moves the stored states from time `after_us` on as the present one moved: rotated by
    /// `rot`, velocity by `dv`, position by `dp`.
    pub(super) fn shift_stored(
        &mut self,
        after_us: u64,
        rot: &UnitQuaternion<f32>,
        dv: &Vector3<f32>,
        dp: &Vector3<f32>,
    ) {
        for k in 0..self.len {
            let i = (self.head + HISTORY - k) % HISTORY;
            if let Some(s) = self.history.get_mut(i) {
                // Newest first, in time order: the rest are older still.
                if s.t_us < after_us {
                    break;
                }
                s.q = rot * s.q;
                s.v += dv;
                s.p += dp;
            }
        }
    }

    /// Applies an error-state correction to the present state and to the stored states after
    /// `t_meas_us` (so the next delayed fix compares like with like). Returns whether the
    /// present state accepted it.
    pub(super) fn apply(&mut self, g: &Gain, t_meas_us: u64) -> bool {
        let dx = &g.fused.dx;
        let dtheta = Vector3::new(dx[ITH], dx[ITH + 1], dx[ITH + 2]);
        let dv = Vector3::new(dx[IV], dx[IV + 1], dx[IV + 2]);
        let dp = Vector3::new(dx[IP], dx[IP + 1], dx[IP + 2]);
        let db = Vector3::new(dx[IBG], dx[IBG + 1], dx[IBG + 2]);
        let rot = crate::math::rotation_from_vector(&dtheta);
        // The state is checked before the covariance changes, and the covariance is changed
        // in place: on refusal both are as they were, and no copy of the matrix is made.
        let state = self.checked_state(
            rot * self.q,
            self.v + dv,
            self.p + dp,
            self.bias + db,
            self.baro_offset + dx[IBO],
        );
        let ok = match state {
            Some(state) if downdate(&mut self.cov, g) => {
                // Finite and exactly symmetric already: only the diagonal's bounds to keep.
                clamp_diagonal(&mut self.cov, MIN_VAR, MAX_VAR);
                self.set_state(state);
                true
            }
            _ => false,
        };
        if ok {
            // One pass over the stored states per measurement, not per component: the
            // corrections compose.
            // 100 µs before the measurement: the state stored at its time moves too.
            let after = t_meas_us.saturating_sub(100);
            let sum = match self.pending {
                Some(s) if s.t_us == after => Snapshot {
                    t_us: after,
                    q: rot * s.q,
                    v: s.v + dv,
                    p: s.p + dp,
                },
                _ => {
                    self.flush_shift();
                    Snapshot {
                        t_us: after,
                        q: rot,
                        v: dv,
                        p: dp,
                    }
                }
            };
            self.pending = Some(sum);
        }
        ok
    }

    /// Carries the pending corrections into the stored states.
    pub(super) fn flush_shift(&mut self) {
        if let Some(s) = self.pending.take() {
            self.shift_stored(s.t_us, &s.q, &s.v, &s.p);
        }
    }
}
