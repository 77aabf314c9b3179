//! PLACEHOLDER for the BVH.
