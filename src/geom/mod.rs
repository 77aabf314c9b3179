//! Pure math: Bézier patches (evaluation, derivatives, de Casteljau split, rational
//! patches), NURBS (knot vectors, Boehm insertion, Bézier decomposition), bounding boxes,
//! rays, outward-rounded interval arithmetic and floating-point helpers. Nothing here knows about files or rendering.
//!
//! Sources: de Casteljau evaluation and subdivision, and the tight box from one split
//! (Lischinski & Gonczarowski 1990, §3.1, Fig. 2); NURBS algorithms from Piegl & Tiller,
//! *The NURBS Book* (A2.2, A5.1, A5.7), as used by Dammertz 2005, §2.8.

pub mod bbox;
pub mod bezier;
pub mod bicubic;
pub mod golden;
pub mod interval;
pub mod nurbs;
pub mod pcurve;
pub mod ray;
pub mod real;
pub mod segment;
pub mod subdiv;
pub mod trim;
pub mod ulp;

pub use bbox::{Aabb, DAabb};
pub use bezier::{BezierPatch, GeomError, MAX_DEGREE};
pub use ray::Ray;
