//! The number types the pair formulas are written over: `f32`, one pair at a time (the
//! reference and the shaders' model), or [`Lanes`], one neighbour against several particles at
//! once (the CPU backend's vectorised loops). A formula generic over [`Real`] is one statement
//! for both; each lane of a [`Lanes`] evaluation does the very operations, in the very order,
//! that the `f32` evaluation does, so its results are the same to the bit.
//!
//! Branches become masks: where the `f32` code skips a term, the lane code computes it and
//! keeps the old sum with [`Real::select`], so a masked lane never even adds zero (which
//! could turn -0 into +0).

use std::fmt::Debug;
use std::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

/// Lanes of a [`Lanes`]: 8 f32 fill an AVX register.
pub const LANES: usize = 8;

/// Which lanes a condition holds for.
pub trait Mask:
    Copy
    + Debug
    + Default
    + PartialEq
    + BitAnd<Output = Self>
    + BitOr<Output = Self>
    + Not<Output = Self>
{
    fn splat(b: bool) -> Self;
    /// Whether any lane holds; the `f32` code's early return when none does.
    fn any(self) -> bool;
}

/// An f32 or a few of them, with the operations the pair formulas use.
pub trait Real:
    Copy
    + Debug
    + Default
    + PartialEq
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    type Mask: Mask;
    /// A phase index per lane.
    type Index: Copy + Debug + Default + PartialEq;
    fn splat(v: f32) -> Self;
    fn sqrt(self) -> Self;
    fn abs(self) -> Self;
    /// `f32::max` in each lane (a NaN loses).
    fn max(self, other: Self) -> Self;
    fn lt(self, other: Self) -> Self::Mask;
    fn ge(self, other: Self) -> Self::Mask;
    fn select(m: Self::Mask, yes: Self, no: Self) -> Self;
    fn index_eq(index: Self::Index, k: u32) -> Self::Mask;
}

impl Mask for bool {
    #[inline(always)]
    fn splat(b: bool) -> bool {
        b
    }
    #[inline(always)]
    fn any(self) -> bool {
        self
    }
}

impl Real for f32 {
    type Mask = bool;
    type Index = u32;
    #[inline(always)]
    fn splat(v: f32) -> f32 {
        v
    }
    #[inline(always)]
    fn sqrt(self) -> f32 {
        f32::sqrt(self)
    }
    #[inline(always)]
    fn abs(self) -> f32 {
        f32::abs(self)
    }
    #[inline(always)]
    fn max(self, other: f32) -> f32 {
        f32::max(self, other)
    }
    #[inline(always)]
    fn lt(self, other: f32) -> bool {
        self < other
    }
    #[inline(always)]
    fn ge(self, other: f32) -> bool {
        self >= other
    }
    #[inline(always)]
    fn select(m: bool, yes: f32, no: f32) -> f32 {
        if m { yes } else { no }
    }
    #[inline(always)]
    fn index_eq(index: u32, k: u32) -> bool {
        index == k
    }
}

/// [`LANES`] f32 side by side.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C, align(32))]
pub struct Lanes(pub [f32; LANES]);

/// A lane mask: all bits set where the condition holds, none where it does not.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C, align(32))]
pub struct LaneMask(pub [u32; LANES]);

/// `items` side by side, lane k taking item k by `put(lanes, k, item)`; lanes past their
/// number repeat the last item (their results are computed and thrown away).
#[inline(always)]
pub fn pack<T, P: Default>(items: &[T], mut put: impl FnMut(&mut P, usize, &T)) -> P {
    let mut out = P::default();
    for k in 0..LANES {
        put(&mut out, k, &items[k.min(items.len() - 1)]);
    }
    out
}

impl Lanes {
    #[inline(always)]
    pub fn from_fn(f: impl FnMut(usize) -> f32) -> Lanes {
        Lanes(std::array::from_fn(f))
    }

    #[inline(always)]
    fn map2(self, other: Lanes, f: impl Fn(f32, f32) -> f32) -> Lanes {
        Lanes(std::array::from_fn(|k| f(self.0[k], other.0[k])))
    }

    #[inline(always)]
    fn test(self, other: Lanes, f: impl Fn(f32, f32) -> bool) -> LaneMask {
        LaneMask(std::array::from_fn(|k| {
            if f(self.0[k], other.0[k]) {
                u32::MAX
            } else {
                0
            }
        }))
    }
}

impl LaneMask {
    #[inline(always)]
    pub fn from_fn(mut f: impl FnMut(usize) -> bool) -> LaneMask {
        LaneMask(std::array::from_fn(|k| if f(k) { u32::MAX } else { 0 }))
    }

    #[inline(always)]
    fn map2(self, other: LaneMask, f: impl Fn(u32, u32) -> u32) -> LaneMask {
        LaneMask(std::array::from_fn(|k| f(self.0[k], other.0[k])))
    }
}

impl BitAnd for LaneMask {
    type Output = LaneMask;
    #[inline(always)]
    fn bitand(self, other: LaneMask) -> LaneMask {
        self.map2(other, |a, b| a & b)
    }
}

impl BitOr for LaneMask {
    type Output = LaneMask;
    #[inline(always)]
    fn bitor(self, other: LaneMask) -> LaneMask {
        self.map2(other, |a, b| a | b)
    }
}

impl Not for LaneMask {
    type Output = LaneMask;
    #[inline(always)]
    fn not(self) -> LaneMask {
        LaneMask(self.0.map(|a| !a))
    }
}

impl Mask for LaneMask {
    #[inline(always)]
    fn splat(b: bool) -> LaneMask {
        LaneMask([if b { u32::MAX } else { 0 }; LANES])
    }
    #[inline(always)]
    fn any(self) -> bool {
        self.0.iter().fold(0, |acc, &m| acc | m) != 0
    }
}

macro_rules! lanes_op {
    ($trait:ident, $method:ident, $op:tt) => {
        impl $trait for Lanes {
            type Output = Lanes;
            #[inline(always)]
            fn $method(self, other: Lanes) -> Lanes {
                self.map2(other, |a, b| a $op b)
            }
        }
    };
}

lanes_op!(Add, add, +);
lanes_op!(Sub, sub, -);
lanes_op!(Mul, mul, *);
lanes_op!(Div, div, /);

impl Neg for Lanes {
    type Output = Lanes;
    #[inline(always)]
    fn neg(self) -> Lanes {
        Lanes(self.0.map(|a| -a))
    }
}

impl Real for Lanes {
    type Mask = LaneMask;
    type Index = [u32; LANES];
    #[inline(always)]
    fn splat(v: f32) -> Lanes {
        Lanes([v; LANES])
    }
    #[inline(always)]
    fn sqrt(self) -> Lanes {
        Lanes(self.0.map(f32::sqrt))
    }
    #[inline(always)]
    fn abs(self) -> Lanes {
        Lanes(self.0.map(f32::abs))
    }
    #[inline(always)]
    fn max(self, other: Lanes) -> Lanes {
        self.map2(other, f32::max)
    }
    #[inline(always)]
    fn lt(self, other: Lanes) -> LaneMask {
        self.test(other, |a, b| a < b)
    }
    #[inline(always)]
    fn ge(self, other: Lanes) -> LaneMask {
        self.test(other, |a, b| a >= b)
    }
    #[inline(always)]
    fn select(m: LaneMask, yes: Lanes, no: Lanes) -> Lanes {
        // On the bits: a blend, never arithmetic.
        Lanes(std::array::from_fn(|k| {
            f32::from_bits((yes.0[k].to_bits() & m.0[k]) | (no.0[k].to_bits() & !m.0[k]))
        }))
    }
    #[inline(always)]
    fn index_eq(index: [u32; LANES], k: u32) -> LaneMask {
        LaneMask::from_fn(|lane| index[lane] == k)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn select_keeps_the_bits_of_the_chosen_lane() {
        let yes = Lanes::from_fn(|k| -0.0 * k as f32 - 0.0);
        let no = Lanes::from_fn(|k| if k == 3 { f32::NAN } else { k as f32 });
        let m = LaneMask::from_fn(|k| k % 2 == 0);
        let s = Lanes::select(m, yes, no);
        for k in 0..LANES {
            let want = if k % 2 == 0 { yes.0[k] } else { no.0[k] };
            assert_eq!(s.0[k].to_bits(), want.to_bits(), "lane {k}");
        }
    }

    #[test]
    fn lanes_round_as_f32_does() {
        // Operands whose products and quotients round, including a NaN and a negative zero.
        let a = Lanes::from_fn(|k| [1.1, -3.7e-5, 7.0, f32::NAN, -0.0, 1e30, 2.5, 1.0 / 3.0][k]);
        let b = Lanes::from_fn(|k| [0.3, 9.1e3, -7.0, 1.0, 5.0, 1e-30, -0.0, 3.0][k]);
        type Pair = (fn(Lanes, Lanes) -> Lanes, fn(f32, f32) -> f32);
        let ops: [Pair; 6] = [
            (|x, y| x + y, |x, y| x + y),
            (|x, y| x - y, |x, y| x - y),
            (|x, y| x * y, |x, y| x * y),
            (|x, y| x / y, |x, y| x / y),
            (|x, y| x.max(y), f32::max),
            (|x, _| -x.abs().sqrt(), |x, _| -x.abs().sqrt()),
        ];
        for (lanes, scalar) in ops {
            let out = lanes(a, b);
            for k in 0..LANES {
                let want = scalar(a.0[k], b.0[k]);
                assert_eq!(out.0[k].to_bits(), want.to_bits(), "lane {k}");
            }
        }
        let lt = a.lt(b);
        let ge = a.ge(b);
        for k in 0..LANES {
            assert_eq!(lt.0[k] != 0, a.0[k] < b.0[k]);
            assert_eq!(ge.0[k] != 0, a.0[k] >= b.0[k]);
        }
        assert!(!LaneMask::splat(false).any());
        assert!(LaneMask::from_fn(|k| k == 7).any());
    }
}
