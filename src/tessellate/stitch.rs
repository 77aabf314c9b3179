//! Triangulating one patch's parameter grid. When every boundary curve has as many
//! segments as the grid side it bounds, the grid is split into quads, two triangles each.
//! Otherwise the inner grid (one cell in from the boundary) is split into quads and the
//! ring between the boundary loop and the inner grid's loop is closed by merging the two
//! loops by parameter, the "zipper" used to join differing edge rates in adaptive
//! tessellation (e.g. Moreton, "Watertight tessellation using forward differencing",
//! HWWS 2001, §4). All triangles run counter-clockwise in (u, v), so their normals agree
//! with ∂S/∂u × ∂S/∂v.

/// A patch's vertices: `interior[j (nu + 1) + i]` for 0 < i < nu, 0 < j < nv, and the four
/// boundary sides counter-clockwise from (0, 0), each with both corners.
pub struct Grid<'a> {
    pub nu: usize,
    pub nv: usize,
    pub interior: &'a [u32],
    pub sides: &'a [Vec<u32>; 4],
}

/// True when each side has exactly the grid's segment count.
pub fn sides_match(nu: usize, nv: usize, sides: &[Vec<u32>; 4]) -> bool {
    let want = [nu, nv, nu, nv];
    sides.iter().zip(want).all(|(s, n)| s.len() == n + 1)
}

impl Grid<'_> {
    pub fn triangulate(&self, emit: &mut dyn FnMut([u32; 3])) {
        if sides_match(self.nu, self.nv, self.sides) {
            self.quads(0, self.nu, 0, self.nv, emit);
        } else {
            self.quads(1, self.nu - 1, 1, self.nv - 1, emit);
            zipper(&self.outer_loop(), &self.inner_loop(), emit);
        }
    }

    /// Vertex at grid point (i, j), on the boundary or inside.
    fn at(&self, i: usize, j: usize) -> u32 {
        let (nu, nv) = (self.nu, self.nv);
        if j == 0 {
            self.sides[0][i]
        } else if i == nu {
            self.sides[1][j]
        } else if j == nv {
            self.sides[2][nu - i]
        } else if i == 0 {
            self.sides[3][nv - j]
        } else {
            self.interior[j * (nu + 1) + i]
        }
    }

    fn quads(&self, i0: usize, i1: usize, j0: usize, j1: usize, emit: &mut dyn FnMut([u32; 3])) {
        for j in j0..j1 {
            for i in i0..i1 {
                let (a, b) = (self.at(i, j), self.at(i + 1, j));
                let (c, d) = (self.at(i + 1, j + 1), self.at(i, j + 1));
                emit([a, b, c]);
                emit([a, c, d]);
            }
        }
    }

    /// The boundary loop with each vertex's perimeter parameter: side s covers [s, s + 1).
    fn outer_loop(&self) -> Vec<(u32, f64)> {
        let mut out = Vec::new();
        for (s, side) in self.sides.iter().enumerate() {
            let n = side.len() - 1;
            out.extend((0..n).map(|k| (side[k], s as f64 + k as f64 / n as f64)));
        }
        out
    }

    /// The loop of the inner grid (grid points one cell in), parameterized side by side
    /// like the outer loop so that corners meet corners.
    fn inner_loop(&self) -> Vec<(u32, f64)> {
        let (nu, nv) = (self.nu, self.nv);
        let (lu, lv) = (nu - 2, nv - 2);
        let mut out = Vec::new();
        let mut side = |s: usize, n: usize, point: &dyn Fn(usize) -> (usize, usize)| {
            for k in 0..n {
                let (i, j) = point(k);
                out.push((self.at(i, j), s as f64 + k as f64 / n as f64));
            }
        };
        side(0, lu, &|k| (1 + k, 1));
        side(1, lv, &|k| (nu - 1, 1 + k));
        side(2, lu, &|k| (nu - 1 - k, nv - 1));
        side(3, lv, &|k| (1, nv - 1 - k));
        if out.is_empty() {
            out.push((self.at(1, 1), 0.0));
        }
        out
    }
}

/// Closes the ring between two counter-clockwise loops by always advancing the loop whose
/// next vertex comes first in parameter; each step makes one triangle.
fn zipper(outer: &[(u32, f64)], inner: &[(u32, f64)], emit: &mut dyn FnMut([u32; 3])) {
    /// Parameters run over [0, 4); the loop's start, seen again at its end, is at 4.
    const LOOP_END: f64 = 4.0;
    let next = |lp: &[(u32, f64)], k: usize| {
        if k + 1 >= lp.len() {
            LOOP_END
        } else {
            lp[k + 1].1
        }
    };
    let (no, ni) = (outer.len(), inner.len());
    let (mut i, mut j) = (0, 0);
    while i < no || j < ni {
        let advance_outer = j == ni || (i < no && next(outer, i) <= next(inner, j));
        if advance_outer {
            emit([outer[i].0, outer[(i + 1) % no].0, inner[j % ni].0]);
            i += 1;
        } else {
            emit([outer[i % no].0, inner[(j + 1) % ni].0, inner[j].0]);
            j += 1;
        }
    }
}
