//! The net stack of the fixed-size SIMD fast paths ([`super::bicubic`], [`super::bilinear`]):
//! the current net and the pending upper child of a split live by value (in registers where
//! the compiler can keep them); both children's boxes and slab tests are computed together,
//! and the farther child (the "nearer side first" order of Dammertz §2.5) is stored to the
//! next free stack slot, which is the only copy of a net a split costs.
//!
//! The search over such a net is compiled three times ([`search_register`]): for AVX-512
//! (32 vector registers, so the current net and both children fit without spilling), for
//! AVX2 (three-operand VEX forms, no register copies) and for the baseline SSE2, chosen
//! once per call by the CPU's features. The source is the same portable code; the
//! instruction sets only change the encoding and the register allocation, never the
//! arithmetic (FMA is not enabled: the compiler never contracts without it being asked,
//! and de Casteljau's averages must round as in the `f64` reference and the neighbours).

use super::config::SubdivisionConfig;
use glam::{Mat4, Vec3A, Vec4};

use super::float::{GBox, GRay};
use super::heuristics::Corners;
use super::jump::JumpOutcome;
use super::param::{ParamCell, Split};
use super::ray_space::RayFrame;
use super::search::{NetStack, Node, SearchHit, search};
use crate::geom::bbox::slab;
use crate::geom::trim::PatchTrim;
use crate::kernel::KernelStats;

/// The boxes of a split's two children (lower first), each with the entry `t` of its slab
/// test if the ray hits it.
pub type ChildTests = [(GBox<f32>, Option<f32>); 2];

/// A control net of fixed size held in SIMD registers, as the search sees it: one step
/// splits it and tests both children against the ray.
pub trait RegisterNet: Copy {
    /// What the split tests need of the ray, in the net's register form, computed once
    /// per search.
    type RayRegisters: Copy;
    fn ray_registers(ray: &GRay<f32>) -> Self::RayRegisters;
    /// Splits at 1/2 in `dir`: `self` becomes the lower half, the upper half is returned
    /// with both halves' boxes (lower first), each with the entry `t` of the slab test
    /// ([`slab`]) clipped to `[ray.tmin, tmax]` if the ray hits it.
    fn split_test(&mut self, dir: Split, ray: &Self::RayRegisters, tmax: f32)
    -> (Self, ChildTests);
    /// Corner points `b(0,0)`, `b(n,0)`, `b(0,m)` for the split heuristics.
    fn corners(&self) -> Corners<f32>;
    /// The jump of [`super::jump`] from this net, whose cell is `cell`: where it lands,
    /// the sub-cell's net, cell, box and entry `t` (clipped to `tmax`). `near` is the
    /// end game's floor: the search may end in a final box of that L1 diameter around a
    /// surface that passes that close to the ray, so the jump keeps such cells too. Only
    /// nets in ray space can jump.
    fn jump(
        &self,
        _cell: ParamCell,
        _ray: &Self::RayRegisters,
        _tmax: f32,
        _near: f32,
    ) -> JumpOutcome<(Self, ParamCell, GBox<f32>, f32)> {
        JumpOutcome::Undecided
    }
}

/// A net of one SSE register per coordinate row ([`super::bicubic`], [`super::bilinear`]),
/// whose boxes come out as `(min, max)` vectors for the SSE slab test.
pub trait LaneNet: Copy {
    /// Splits at 1/2 in `dir`: `self` becomes the lower half, the upper half is returned.
    fn split_in_place(&mut self, dir: Split) -> Self;
    /// The control boxes of two nets as `(min, max)` vectors, computed together so that
    /// their horizontal reductions share shuffles.
    fn bounds_pair(a: &Self, b: &Self) -> [(Vec3A, Vec3A); 2];
    /// Corner points `b(0,0)`, `b(n,0)`, `b(0,m)` for the split heuristics.
    fn corners(&self) -> Corners<f32>;

    /// The control box of the net.
    fn bounds(&self) -> GBox<f32> {
        let [(min, max), _] = Self::bounds_pair(self, self);
        GBox {
            min: min.to_array(),
            max: max.to_array(),
        }
    }
}

impl<N: LaneNet> RegisterNet for N {
    /// Origin, reciprocal direction and `tmin`.
    type RayRegisters = (Vec3A, Vec3A, f32);

    #[inline(always)]
    fn ray_registers(ray: &GRay<f32>) -> Self::RayRegisters {
        (
            Vec3A::from_array(ray.origin),
            Vec3A::from_array(ray.inv_dir),
            ray.tmin,
        )
    }

    #[inline(always)]
    fn split_test(
        &mut self,
        dir: Split,
        &(origin, inv_dir, tmin): &Self::RayRegisters,
        tmax: f32,
    ) -> (Self, ChildTests) {
        let upper = self.split_in_place(dir);
        let tests = N::bounds_pair(self, &upper).map(|(min, max)| {
            let hit = slab(min, max, origin, inv_dir, tmin, tmax).map(|(t, _)| t);
            (
                GBox {
                    min: min.to_array(),
                    max: max.to_array(),
                },
                hit,
            )
        });
        (upper, tests)
    }

    #[inline(always)]
    fn corners(&self) -> Corners<f32> {
        LaneNet::corners(self)
    }
}

/// Horizontal reduction of three registers with `f` (lane-wise min or max) into the lanes
/// x, y, z of one: a 4×4 transpose and two lane-wise steps instead of three separate
/// two-shuffle reductions and their scalar extractions.
#[inline(always)]
pub fn reduce3(a: Vec4, b: Vec4, c: Vec4, f: impl Fn(Vec4, Vec4) -> Vec4) -> Vec3A {
    let m = Mat4::from_cols(a, b, c, c).transpose();
    Vec3A::from_vec4(f(f(m.x_axis, m.y_axis), f(m.z_axis, m.w_axis)))
}

/// The current net and the pending upper child of the last split by value (in registers
/// where the compiler can keep them); the pushed nets in `slots[..top]`. A split writes the
/// lower child over `cur`; pushing the farther child is one store of it, whichever it is.
pub struct RegisterStack<'a, N: RegisterNet> {
    pub ray: N::RayRegisters,
    /// See [`NetStack::end_game_floor`].
    pub end_game_floor: f32,
    pub cur: N,
    pub pending: N,
    pub slots: &'a mut Vec<N>,
    pub top: usize,
}

impl<'a, N: RegisterNet> RegisterStack<'a, N> {
    /// A stack holding only `root`; `slots` is reused scratch.
    #[inline(always)]
    pub fn new(root: N, ray: &GRay<f32>, slots: &'a mut Vec<N>) -> Self {
        Self::with_registers(root, N::ray_registers(ray), 0.0, slots)
    }

    /// A stack holding only `root`, testing boxes with `ray` (in whatever frame the nets
    /// are) and ending the end game at `end_game_floor` at the latest.
    #[inline(always)]
    pub fn with_registers(
        root: N,
        ray: N::RayRegisters,
        end_game_floor: f32,
        slots: &'a mut Vec<N>,
    ) -> Self {
        RegisterStack {
            ray,
            end_game_floor,
            cur: root,
            pending: root,
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
    fn split_test(&mut self, dir: Split, _ray: &GRay<f32>, tmax: f32) -> ChildTests {
        let tests;
        (self.pending, tests) = self.cur.split_test(dir, &self.ray, tmax);
        tests
    }

    #[inline(always)]
    fn push_far(&mut self, far_is_lower: bool) {
        let far = if far_is_lower {
            std::mem::replace(&mut self.cur, self.pending)
        } else {
            self.pending
        };
        match self.slots.get_mut(self.top) {
            Some(slot) => *slot = far,
            None => self.slots.push(far),
        }
        self.top += 1;
    }

    #[inline(always)]
    fn keep(&mut self, lower: bool) {
        if !lower {
            self.cur = self.pending;
        }
    }

    #[inline(always)]
    fn pop(&mut self) {
        if let Some(top) = self.top.checked_sub(1) {
            self.top = top;
            self.cur = self.slots[top];
        }
    }

    #[inline(always)]
    fn try_jump(&mut self, cell: ParamCell, tmax: f32) -> JumpOutcome<(ParamCell, GBox<f32>, f32)> {
        self.cur
            .jump(cell, &self.ray, tmax, self.end_game_floor)
            .and_then(|(net, sub, bbox, t)| {
                self.cur = net;
                JumpOutcome::Landed((sub, bbox, t))
            })
    }

    fn end_game_floor(&self) -> f32 {
        self.end_game_floor
    }
}

/// What one search of a register net is asked: the net's root box, the ray (and its
/// ray-space frame where the ray is searched in ray space, which only the AVX-512 net
/// supports), the settings, and whether any hit will do (shadow rays).
#[derive(Clone, Copy, Debug)]
pub struct Query<'a> {
    pub root: GBox<f32>,
    pub ray: &'a GRay<f32>,
    pub frame: Option<&'a RayFrame>,
    pub cfg: &'a SubdivisionConfig,
    pub any_hit: bool,
    /// The patch's trim loops, if it has any ([`super::search::search`]).
    pub trim: Option<&'a PatchTrim>,
    /// A cell the ray provably does not cross ([`super::trivial`]).
    pub trivial: Option<ParamCell>,
}

/// The reusable buffers of a register-net search: the pushed nets and the search nodes.
pub type Scratch<N> = (Vec<N>, Vec<Node<f32>>);

/// The search of [`super::search`] on a register net, compiled for the best instruction set
/// the CPU offers (see the module documentation).
#[inline(always)]
pub fn search_register<N: RegisterNet>(
    net: N,
    scratch: &mut Scratch<N>,
    q: Query,
    stats: &mut KernelStats,
) -> Option<SearchHit<f32>> {
    #[cfg(target_arch = "x86_64")]
    {
        if is_x86_feature_detected!("avx512f") && is_x86_feature_detected!("avx512vl") {
            // SAFETY: the CPU has the features the function is compiled for.
            return unsafe { search_avx512(net, scratch, q, stats) };
        }
        if is_x86_feature_detected!("avx2") {
            // SAFETY: as above.
            return unsafe { search_avx2(net, scratch, q, stats) };
        }
    }
    search_portable(net, scratch, q, stats)
}

/// The search itself, inlined into each instruction-set version.
#[inline(always)]
fn search_portable<N: RegisterNet>(
    net: N,
    (slots, nodes): &mut Scratch<N>,
    q: Query,
    stats: &mut KernelStats,
) -> Option<SearchHit<f32>> {
    let mut nets = RegisterStack::new(net, q.ray, slots);
    search(
        &mut nets, nodes, q.root, q.ray, false, q.cfg, q.any_hit, q.trim, q.trivial, stats,
    )
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,avx512f,avx512vl")]
fn search_avx512<N: RegisterNet>(
    net: N,
    scratch: &mut Scratch<N>,
    q: Query,
    stats: &mut KernelStats,
) -> Option<SearchHit<f32>> {
    search_portable(net, scratch, q, stats)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn search_avx2<N: RegisterNet>(
    net: N,
    scratch: &mut Scratch<N>,
    q: Query,
    stats: &mut KernelStats,
) -> Option<SearchHit<f32>> {
    search_portable(net, scratch, q, stats)
}
