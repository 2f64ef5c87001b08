//! When the air leaves a particle's external acceleration at gravity to the bit, so that a
//! kernel may leave the drag out (shared by the fused frame's prediction and the explicit
//! springs' integration; no imports, so that any module may use it).

/// Whether, along an axis with gravity component `g`, the air with drag coefficient `drag`
/// leaves [`crate::forces::Forces::acceleration_of`] at g to the bit: no drag (c_d = +0) and
/// g not −0. Then g + c_d (v_wind − v) = g for every finite v (c_d (v_wind − v) is ±0, and
/// g + ±0 = g unless g is −0), so a kernel may leave the drag out.
pub(crate) fn still_air(drag: f64, g: f64) -> bool {
    drag.to_bits() == 0 && g.to_bits() != (-0.0f64).to_bits()
}
