//! The net stack of the fixed-size SIMD fast paths ([`super::bicubic`], [`super::bilinear`]):
//! the current net lives by value (in registers where the compiler can keep it), a split
//! writes the lower child over it and the upper child beside it, and only the farther hit
//! child is copied to the stack (the "nearer side first" order of Dammertz §2.5).

use super::float::GBox;
use super::heuristics::Corners;
use super::param::Split;
use super::search::NetStack;

/// A control net of fixed size held in SIMD registers.
pub trait RegisterNet: Copy {
    /// Splits at 1/2 in `dir`: `self` becomes the lower half, the upper half is returned.
    fn split_in_place(&mut self, dir: Split) -> Self;
    /// The control box of the net.
    fn bounds(&self) -> GBox<f32>;
    /// Corner points `b(0,0)`, `b(n,0)`, `b(0,m)` for the split heuristics.
    fn corners(&self) -> Corners<f32>;
}

/// The current net by value, the pending upper child, and the pushed nets.
pub struct RegisterStack<'a, N> {
    pub cur: N,
    pub upper: N,
    pub pushed: &'a mut Vec<N>,
}

impl<'a, N: RegisterNet> RegisterStack<'a, N> {
    /// A stack holding only `root`; `pushed` is reused scratch (cleared here).
    #[inline(always)]
    pub fn new(root: N, pushed: &'a mut Vec<N>) -> Self {
        pushed.clear();
        RegisterStack {
            cur: root,
            upper: root,
            pushed,
        }
    }
}

impl<N: RegisterNet> NetStack<f32> for RegisterStack<'_, N> {
    #[inline(always)]
    fn corners(&self) -> Corners<f32> {
        self.cur.corners()
    }

    #[inline(always)]
    fn split(&mut self, dir: Split) -> [GBox<f32>; 2] {
        self.upper = self.cur.split_in_place(dir);
        [self.cur.bounds(), self.upper.bounds()]
    }

    #[inline(always)]
    fn push_far(&mut self, far_is_lower: bool) {
        if far_is_lower {
            self.pushed.push(self.cur);
            self.cur = self.upper;
        } else {
            self.pushed.push(self.upper);
        }
    }

    #[inline(always)]
    fn keep(&mut self, lower: bool) {
        if !lower {
            self.cur = self.upper;
        }
    }

    #[inline(always)]
    fn pop(&mut self) {
        if let Some(n) = self.pushed.pop() {
            self.cur = n;
        }
    }
}
