//! The numbers LG90 reports, transcribed from the paper (Lischinski & Gonczarowski 1990,
//! §7): total rays per test case from Table 1, and Tables 2–6, one per test case, with the
//! columns TOTH, ISRT, SCAN, ITBUF, PEANO.

/// Table 1, "total num. of rays", test cases 1–5 at 512².
pub const TOTAL_RAYS: [u64; 5] = [482994, 437452, 773479, 1934605, 925193];

/// One of Tables 2–6.
pub struct PaperTable {
    /// Rows in [`super::Statistic::PAPER_ROWS`] order, columns TOTH, ISRT, SCAN, ITBUF,
    /// PEANO.
    pub rows: [[f64; 5]; 8],
    /// Cache misses per surface and cache hit ratio (percent), columns SCAN, ITBUF, PEANO
    /// (the paper leaves them blank for TOTH and ISRT, which cache nothing).
    pub cache: [[f64; 3]; 2],
}

/// Table 2: processing statistics for test case 1 (1 reflective teapot).
pub const TABLE_2: PaperTable = PaperTable {
    rows: [
        [1.00, 0.90, 0.26, 0.24, 0.24],
        [3.04, 3.02, 3.02, 3.02, 3.02],
        [2.11, 2.10, 1.06, 1.04, 1.03],
        [18.30, 17.52, 42.12, 44.23, 44.84],
        [7.42, 6.68, 2.82, 2.59, 2.56],
        [1.05, 0.37, 0.37, 0.37, 0.37],
        [1.36, 1.44, 1.08, 1.07, 1.06],
        [0.134, 0.155, 0.027, 0.026, 0.025],
    ],
    cache: [[104.72, 66.59, 59.84], [99.00, 99.35, 99.39]],
};

/// Table 3: processing statistics for test case 2 (50 plain teapots, depth 1).
pub const TABLE_3: PaperTable = PaperTable {
    rows: [
        [1.00, 0.93, 0.30, 0.29, 0.29],
        [6.88, 6.81, 6.82, 6.82, 6.82],
        [2.81, 2.78, 1.33, 1.27, 1.27],
        [27.68, 26.88, 54.69, 57.04, 57.40],
        [7.62, 7.10, 2.93, 2.72, 2.73],
        [1.02, 0.50, 0.51, 0.51, 0.51],
        [1.37, 1.38, 1.14, 1.12, 1.11],
        [0.146, 0.150, 0.041, 0.040, 0.036],
    ],
    cache: [[6.16, 1.95, 1.13], [94.59, 96.74, 96.93]],
};

/// Table 4: processing statistics for test case 3 (50 reflective teapots).
pub const TABLE_4: PaperTable = PaperTable {
    rows: [
        [1.00, 0.91, 0.35, 0.30, 0.29],
        [8.42, 8.35, 8.36, 8.36, 8.36],
        [3.62, 3.58, 1.96, 1.72, 1.71],
        [36.81, 35.59, 61.95, 70.18, 70.99],
        [11.06, 10.20, 5.31, 4.50, 4.47],
        [1.17, 0.41, 0.42, 0.42, 0.42],
        [1.32, 1.34, 1.27, 1.21, 1.19],
        [0.128, 0.135, 0.061, 0.051, 0.048],
    ],
    cache: [[117.98, 72.20, 68.42], [84.50, 88.97, 89.42]],
};

/// Table 5: processing statistics for test case 4 (50 reflective teapots, 6 lights).
pub const TABLE_5: PaperTable = PaperTable {
    rows: [
        [1.00, 0.88, 0.28, 0.26, 0.26],
        [8.37, 8.17, 8.20, 8.20, 8.20],
        [3.54, 3.45, 1.75, 1.58, 1.58],
        [37.32, 35.33, 63.77, 71.60, 72.29],
        [11.45, 10.20, 4.90, 4.25, 4.24],
        [1.15, 0.15, 0.16, 0.15, 0.15],
        [1.33, 1.34, 1.27, 1.20, 1.19],
        [0.131, 0.135, 0.062, 0.050, 0.048],
    ],
    cache: [[159.17, 107.47, 102.77], [90.72, 92.90, 93.14]],
};

/// Table 6: processing statistics for test case 5 (100 reflective teapots).
pub const TABLE_6: PaperTable = PaperTable {
    rows: [
        [1.00, 0.91, 0.40, 0.36, 0.35],
        [10.67, 10.56, 10.57, 10.57, 10.57],
        [4.14, 4.10, 2.43, 2.19, 2.18],
        [42.39, 40.96, 66.12, 73.63, 74.41],
        [12.29, 11.31, 6.48, 5.65, 5.62],
        [1.24, 0.43, 0.44, 0.44, 0.44],
        [1.32, 1.33, 1.33, 1.27, 1.26],
        [0.124, 0.129, 0.070, 0.061, 0.058],
    ],
    cache: [[154.38, 115.93, 111.47], [74.46, 78.63, 79.22]],
};
