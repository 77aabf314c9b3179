//! Work counters of the Toth kernel: the rows of Lischinski & Gonczarowski's Tables 2–6
//! (§7.1) that a single ray–patch search produces.

/// Counters summed over kernel calls.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TothStats {
    /// Patches that entered the search loop ("surfaces searched").
    pub searches: u64,
    /// Boxes popped from the candidate list and tested with Krawczyk's operator ("search
    /// iterations").
    pub search_iterations: u64,
    /// Ray–box tests of candidate sub-patches (in ray coordinates).
    pub box_tests: u64,
    /// Boxes excluded because `K ∩ X` was empty.
    pub excluded: u64,
    /// Boxes bisected (Toth's split of `K ∩ X`).
    pub bisections: u64,
    /// Safe regions in which simple Newton iteration was started ("Newton starts").
    pub newton_starts: u64,
    /// Simple Newton iterations, over all starts ("Newton iterations / call" is this over
    /// `newton_starts`).
    pub newton_iterations: u64,
    /// Sum of the widths of the safe regions Newton started in ("av. width of safe
    /// regions" is this over `newton_starts`).
    pub safe_width_sum: f64,
    /// Shadow rays answered by a safe region alone, without Newton (ISRT, §6).
    pub early_outs: u64,
    /// Boxes too small for analysis, answered as hits (LG90 §4.2 step 4).
    pub final_boxes: u64,
    /// Searches cut off by the iteration bound.
    pub cut_off: u64,
    /// Boxes of the surface a secondary ray leaves dropped by each of LG90's three
    /// triviality tests (§6): the box's, `K`'s, and the safe region's root's ray parameter
    /// proved below `tmin`.
    pub trivial: [u64; 3],
}

impl TothStats {
    pub fn add(&mut self, o: &TothStats) {
        self.searches += o.searches;
        self.search_iterations += o.search_iterations;
        self.box_tests += o.box_tests;
        self.excluded += o.excluded;
        self.bisections += o.bisections;
        self.newton_starts += o.newton_starts;
        self.newton_iterations += o.newton_iterations;
        self.safe_width_sum += o.safe_width_sum;
        self.early_outs += o.early_outs;
        self.final_boxes += o.final_boxes;
        self.cut_off += o.cut_off;
        for (a, b) in self.trivial.iter_mut().zip(o.trivial) {
            *a += b;
        }
    }

    /// Mean simple Newton iterations per start.
    pub fn newton_iterations_per_call(&self) -> f64 {
        ratio(self.newton_iterations as f64, self.newton_starts)
    }

    /// Mean width of the safe regions Newton started in.
    pub fn mean_safe_width(&self) -> f64 {
        ratio(self.safe_width_sum, self.newton_starts)
    }
}

fn ratio(x: f64, n: u64) -> f64 {
    if n == 0 { 0.0 } else { x / n as f64 }
}
