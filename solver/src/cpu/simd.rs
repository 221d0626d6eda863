//! Which vector instructions the lane loops (`physics::lanes`) compile to. The crate is built
//! for the baseline of its target (SSE2 on x86-64, four f32 a register), so a pass that runs
//! inside [`dispatch`] is compiled a second time for AVX2 (eight) and that copy runs where
//! the CPU has it. Both copies do the same IEEE operations lane by lane: the results are the
//! same to the bit on either. Only what LLVM inlines into [`avx2`] is in the AVX2 copy: a
//! function it keeps apart is compiled once, for the baseline. So the closure handed to
//! [`dispatch`] is `#[inline(always)]`, and so is the visitor a pass hands the cell list
//! (`Grid::group_cells`): until both were, the force pass's pair loops ran on four lanes (16 %
//! of the CI flume's time in one function of SSE code). (A third copy for AVX-512F/VL, the
//! same eight lanes with twice the registers, ran the CI flume 30 % slower here: it is not
//! built.)

/// Runs `f`, compiled for AVX2 where the CPU has it.
#[inline(always)]
pub fn dispatch<R>(f: impl FnOnce() -> R) -> R {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has AVX2, as checked just above.
        return unsafe { avx2(f) };
    }
    f()
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn avx2<R>(f: impl FnOnce() -> R) -> R {
    f()
}
