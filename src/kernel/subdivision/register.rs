//! The net stack of the fixed-size SIMD fast paths ([`super::bicubic`], [`super::bilinear`]):
//! the current net lives by value (in registers where the compiler can keep it), a split
//! writes the lower child over it and the upper child into the next free stack slot, so
//! that pushing the upper child (the "nearer side first" order of Dammertz §2.5) costs no
//! copy and pushing the lower one costs a swap.

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

/// The current net by value; the pushed nets in `slots[..top]` and the pending upper child
/// of the last split in `slots[top]`, so that pushing it is no copy.
pub struct RegisterStack<'a, N> {
    pub cur: N,
    pub slots: &'a mut Vec<N>,
    pub top: usize,
}

impl<'a, N: RegisterNet> RegisterStack<'a, N> {
    /// A stack holding only `root`; `slots` is reused scratch.
    #[inline(always)]
    pub fn new(root: N, slots: &'a mut Vec<N>) -> Self {
        if slots.is_empty() {
            slots.push(root);
        }
        RegisterStack {
            cur: root,
            slots,
            top: 0,
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
        let upper = &mut self.slots[self.top];
        *upper = self.cur.split_in_place(dir);
        [self.cur.bounds(), upper.bounds()]
    }

    #[inline(always)]
    fn push_far(&mut self, far_is_lower: bool) {
        if far_is_lower {
            std::mem::swap(&mut self.cur, &mut self.slots[self.top]);
        }
        self.top += 1;
        if self.slots.len() == self.top {
            self.slots.push(self.cur);
        }
    }

    #[inline(always)]
    fn keep(&mut self, lower: bool) {
        if !lower {
            self.cur = self.slots[self.top];
        }
    }

    #[inline(always)]
    fn pop(&mut self) {
        if let Some(top) = self.top.checked_sub(1) {
            self.top = top;
            self.cur = self.slots[top];
        }
    }
}
