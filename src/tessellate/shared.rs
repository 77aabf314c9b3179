//! Boundary samples shared between trimmed faces, so that neighbouring faces meet without
//! cracks. Each trimmed face is triangulated from its own loops, and two faces that share
//! an edge in the model each hold their own copy of it, in their own parameters (CAD
//! exporters fit them separately, to the exporter's tolerance); sampled apart, the two
//! meshes would meet only approximately.
//!
//! Here a sample of one face that lies within [`EDGE_FRACTION`] of the model's size of
//! another face's exact trim curve (the curve's image on that face's surface, found by a
//! golden-section search on the curve between its two nearest samples) is a point of an
//! edge the two faces share. It is added to the other face's loop at that parameter, unless
//! a sample of the other face already lies that close to it, and the samples found to be
//! one point are given one vertex position: the exact surface point of the first of them.
//! Both faces then have the same samples, in the same order, along the edge they share, so
//! their boundary edges are the same segments and every edge of a closed solid's mesh is
//! used by exactly two triangles. A face's loops are matched against its own other pieces
//! too: the seam of a closed surface is an edge a face shares with itself.
//!
//! Why by geometry rather than by the B-rep's edges: the scene keeps each face's loops as
//! trim curves in its own parameters (split into monotone Bézier pieces for the kernels),
//! not which face an edge is shared with, and bare trimmed surface sets (IGES 144 without a
//! 186 solid, OBJ free-form) have no such topology at all, so one rule serves every input.

use std::collections::HashMap;

use glam::DVec3;

use super::cubes::Cubes;
use super::trimmed::{Face, Sample};
use crate::geom::segment::distance_to_segment;

/// How near (as a fraction of the diagonal of all trimmed faces' boundary samples) a
/// sample must come to another face's exact trim curve to be a point of an edge they
/// share: the tolerance the STEP reader asks its computed pcurves to meet
/// (`PCURVE_TOLERANCE`, 10⁻⁴ of the model), the loosest end of the 10⁻⁷ to 10⁻⁴ of a
/// part that CAD systems write edges to (IGES 5.3 §2.2.4.3, global parameter 19,
/// "minimum resolution").
pub const EDGE_FRACTION: f64 = 1e-4;

/// How near, as a fraction of the join distance, a sample of the other face must lie to
/// the foot of a sample on the other face's curve for the two to be one point. Along an
/// edge the two faces' samples are distinct points of one curve, often nearer each other
/// than the join distance (a curve sampled densely where it turns, the ends of the
/// monotone pieces each face splits its own parameter curve into); joined, each would move
/// along the curve away from its own parameters, off its face's surface by up to the join
/// distance. At 10⁻² of it (10⁻⁶ of the model, the readers' chord tolerance
/// [`crate::formats::cad::CHORD_TOLERANCE`]) only samples that are one point are joined;
/// otherwise the other face gains the sample at its foot, so both faces still have both
/// samples at one position each.
const ALONG_FRACTION: f64 = 1e-2;

/// Golden-section steps for the nearest point of a trim curve: 0.618⁶⁰ ≈ 3·10⁻¹³ of the
/// segment's parameter range, below `f64` resolution of any position along it.
const GOLDEN_STEPS: usize = 60;

/// Where a sample is: face, piece, index in the piece's samples.
type At = (usize, usize, usize);

/// Joins the boundary samples of `faces` that are one point (module docs), adding samples
/// where a face lacks its neighbour's, and sets every sample's position. Returns the
/// distance within which samples were joined.
pub(super) fn join(faces: &mut [Face]) -> f64 {
    let refs: Vec<At> = faces
        .iter()
        .enumerate()
        .flat_map(|(f, face)| {
            face.samples
                .iter()
                .enumerate()
                .flat_map(move |(k, line)| (0..line.len()).map(move |i| (f, k, i)))
        })
        .collect();
    let point = |faces: &[Face], (f, k, i): At| faces[f].samples[k][i].point;
    let (lo, hi) = refs
        .iter()
        .map(|&at| point(faces, at))
        .filter(|p| p.is_finite())
        .fold(
            (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
            |(lo, hi), p| (lo.min(p), hi.max(p)),
        );
    let size = (hi - lo).length();
    if !(size.is_finite() && size > 0.0) {
        return 0.0;
    }
    let eps = size * EDGE_FRACTION;
    let grid = SegmentGrid::new(faces, eps, size, lo);
    // The first id of each piece's samples; ids past `refs.len()` are samples added below.
    let mut first = HashMap::new();
    for (id, &(f, k, i)) in refs.iter().enumerate() {
        if i == 0 {
            first.insert((f, k), id);
        }
    }
    let mut sets = UnionFind::new(refs.len());
    let mut added: HashMap<(usize, usize), Vec<(f64, usize)>> = HashMap::new();
    let mut points: Vec<DVec3> = refs.iter().map(|&at| point(faces, at)).collect();
    for (id, &(f, k, _)) in refs.iter().enumerate() {
        let p = points[id];
        if !p.is_finite() {
            continue;
        }
        for ((g, m), t) in grid.nearest_curves(faces, p, (f, k), eps) {
            let line = &faces[g].samples[m];
            let j = line.partition_point(|s| s.t < t);
            let foot = faces[g].sample(m, t).point;
            let existing = [j.wrapping_sub(1), j]
                .into_iter()
                .filter(|&x| {
                    x < line.len() && (line[x].point - foot).length() <= eps * ALONG_FRACTION
                })
                .min_by(|&x, &y| {
                    (line[x].point - p)
                        .length()
                        .total_cmp(&(line[y].point - p).length())
                });
            // Joining is refused where the two sets' points are farther apart than the join
            // distance (dense samples along an edge would otherwise chain into one point);
            // the sample is then added instead, so both faces still have it. A sample at
            // the very parameter of an existing one is that one.
            let joinable = |x: usize, sets: &mut UnionFind| {
                let other = first[&(g, m)] + x;
                line[x].t == t || (points[sets.find(id)] - points[sets.find(other)]).length() <= eps
            };
            match existing.filter(|&x| joinable(x, &mut sets)) {
                Some(x) => sets.union(id, first[&(g, m)] + x),
                None => {
                    let new = sets.add();
                    points.push(faces[g].sample(m, t).point);
                    sets.union(id, new);
                    added.entry((g, m)).or_default().push((t, new));
                }
            }
        }
    }
    // Each set's position: the exact point of its first sample (the lowest id).
    let mut position: HashMap<usize, DVec3> = HashMap::new();
    let ids = points.len();
    for (id, &p) in points.iter().enumerate().take(ids) {
        position.entry(sets.find(id)).or_insert(p);
    }
    for (id, &(f, k, i)) in refs.iter().enumerate() {
        faces[f].samples[k][i].position = position[&sets.find(id)];
    }
    for ((g, m), mut extra) in added {
        extra.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut line: Vec<Sample> = extra
            .iter()
            .map(|&(t, id)| Sample {
                position: position[&sets.find(id)],
                ..faces[g].sample(m, t)
            })
            .collect();
        line.append(&mut faces[g].samples[m]);
        line.sort_by(|a, b| a.t.total_cmp(&b.t));
        faces[g].samples[m] = line;
    }
    eps
}

/// Disjoint sets of sample ids, with path halving.
struct UnionFind(Vec<usize>);

impl UnionFind {
    fn new(n: usize) -> Self {
        UnionFind((0..n).collect())
    }

    fn add(&mut self) -> usize {
        self.0.push(self.0.len());
        self.0.len() - 1
    }

    fn find(&mut self, mut x: usize) -> usize {
        while self.0[x] != x {
            self.0[x] = self.0[self.0[x]];
            x = self.0[x];
        }
        x
    }

    /// Joins the sets of `a` and `b`; the lower root stays the root.
    fn union(&mut self, a: usize, b: usize) {
        let (a, b) = (self.find(a), self.find(b));
        let (lo, hi) = (a.min(b), a.max(b));
        self.0[hi] = lo;
    }
}

/// The segments between consecutive samples of every piece, hashed into cubes: each
/// segment into the cubes of points along it at most half a cube apart, so that a point
/// within half a cube of the segment lies in a cube next to one of them. A segment's
/// `reach` is how far a point of its exact curve may lie from it: the join distance plus
/// twice the largest distance of the curve from the chord at the chord probes.
struct SegmentGrid {
    /// Per cube: face, piece, segment (from sample `s` to `s + 1`), reach.
    cubes: Cubes<(u32, u32, u32, Reach)>,
}

/// A segment's reach, ordered by value (`f64::total_cmp`) so that entries sort and
/// deduplicate in the cubes.
#[derive(Clone, Copy)]
struct Reach(f64);

impl PartialEq for Reach {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other).is_eq()
    }
}

impl Eq for Reach {}

impl PartialOrd for Reach {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Reach {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.0.total_cmp(&other.0)
    }
}

impl SegmentGrid {
    fn new(faces: &[Face], eps: f64, size: f64, origin: DVec3) -> Self {
        let mut segments = Vec::new();
        let mut widest = 0.0f64;
        for (f, face) in faces.iter().enumerate() {
            for (k, line) in face.samples.iter().enumerate() {
                for (s, w) in line.windows(2).enumerate() {
                    let (a, b) = (w[0].point, w[1].point);
                    if !(a.is_finite() && b.is_finite()) {
                        continue;
                    }
                    let bow = super::edge::CHORD_PROBES
                        .iter()
                        .map(|&x| {
                            let q = face.sample(k, w[0].t + (w[1].t - w[0].t) * x).point;
                            distance_to_segment(q, a, b)
                        })
                        .fold(0.0, f64::max);
                    let reach = eps + 2.0 * bow;
                    if reach.is_finite() {
                        widest = widest.max(reach);
                        segments.push((f as u32, k as u32, s as u32, reach, a, b));
                    }
                }
            }
        }
        // Cubes no smaller than 1/256 of the model, so that long segments are walked in a
        // bounded number of steps.
        let cube = (2.0 * widest).max(size / 256.0);
        let mut cubes = Cubes::new(cube, origin);
        for (f, k, s, reach, a, b) in segments {
            cubes.insert_segment(a, b, 0.5 * cube, (f, k, s, Reach(reach)));
        }
        SegmentGrid { cubes }
    }

    /// For every piece other than `own` whose exact curve comes within `eps` of `p`, the
    /// piece and the parameter of its nearest point.
    fn nearest_curves(
        &self,
        faces: &[Face],
        p: DVec3,
        own: (usize, usize),
        eps: f64,
    ) -> Vec<((usize, usize), f64)> {
        // The segments within their reach of `p`, each once and in order (a segment is
        // filed in several cubes): the cheap distance first, so that only the few left are
        // sorted and searched along their exact curves.
        let mut candidates = Vec::new();
        self.cubes.visit_near(p, |c @ (f, k, s, Reach(reach))| {
            let piece = (f as usize, k as usize);
            if piece != own {
                let line = &faces[piece.0].samples[piece.1];
                let (a, b) = (line[s as usize].point, line[s as usize + 1].point);
                if distance_to_segment(p, a, b) <= reach {
                    candidates.push(c);
                }
            }
        });
        candidates.sort_unstable();
        candidates.dedup();
        let mut best: Vec<((usize, usize), f64, f64)> = Vec::new();
        for (f, k, s, _) in candidates {
            let piece = (f as usize, k as usize);
            let line = &faces[piece.0].samples[piece.1];
            let (a, b) = (line[s as usize], line[s as usize + 1]);
            let (t, d) = nearest_on_curve(&faces[piece.0], piece.1, a.t, b.t, p);
            if d > eps {
                continue;
            }
            match best.iter_mut().find(|e| e.0 == piece) {
                Some(e) if d < e.2 => *e = (piece, t, d),
                Some(_) => {}
                None => best.push((piece, t, d)),
            }
        }
        // A foot at a piece's end, farther than one point, is where a sample lies beyond
        // that piece along the face's loop: the piece next to it on the same face holds
        // its foot inside, and only that one is the sample's place.
        let tight = eps * ALONG_FRACTION;
        let inside: Vec<usize> = best
            .iter()
            .filter(|e| e.1 > 0.0 && e.1 < 1.0)
            .map(|e| e.0.0)
            .collect();
        best.into_iter()
            .filter(|&((g, _), t, d)| t > 0.0 && t < 1.0 || d <= tight || !inside.contains(&g))
            .map(|(piece, t, _)| (piece, t))
            .collect()
    }
}

/// The parameter in `[t0, t1]` of piece `k` of `face` whose surface point is nearest `p`,
/// and its distance: golden-section search (Kiefer 1953), the interval's ends included.
fn nearest_on_curve(face: &Face, k: usize, t0: f64, t1: f64, p: DVec3) -> (f64, f64) {
    let f = |t: f64| (face.sample(k, t).point - p).length();
    let mid = crate::geom::golden::minimize(f, t0, t1, GOLDEN_STEPS);
    [(t0, f(t0)), (t1, f(t1)), (mid, f(mid))]
        .into_iter()
        .min_by(|x, y| x.1.total_cmp(&y.1))
        .unwrap_or((mid, f(mid)))
}
