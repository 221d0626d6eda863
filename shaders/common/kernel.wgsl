// Wendland C2 kernel (Eq. 8), support 2h; reference: solver/src/physics/kernel.rs.

fn kernel_w(r: f32) -> f32 {
    let q = r / params.h;
    if (q >= 2.0) {
        return 0.0;
    }
    let a = 1.0 - 0.5 * q;
    let a2 = a * a;
    return params.kernel_ad * a2 * a2 * (2.0 * q + 1.0);
}

// F such that grad_i W_ij = (x_i - x_j) F.
fn kernel_grad_factor(r: f32) -> f32 {
    let q = r / params.h;
    if (q >= 2.0) {
        return 0.0;
    }
    let a = 1.0 - 0.5 * q;
    return params.kernel_ad * (-5.0 / (params.h * params.h)) * a * a * a;
}
