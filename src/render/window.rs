//! Pixel windows of an image: `render --crop X0,X1,Y0,Y1` (pbrt-v4's `--pixelbounds`, upper
//! bounds exclusive), `render --tile K/N` (the K-th of N bands of rows, K from 0, as a job
//! array numbers its tasks), and the check `merge` makes that pieces cover an image once.

use std::fmt;

/// A rectangle of pixels `x0..x1` × `y0..y1` (upper bounds exclusive) of a `width`×`height`
/// image.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Window {
    pub x0: u32,
    pub x1: u32,
    pub y0: u32,
    pub y1: u32,
}

impl Window {
    /// The whole image.
    pub fn full(width: u32, height: u32) -> Window {
        Window {
            x0: 0,
            x1: width,
            y0: 0,
            y1: height,
        }
    }

    pub fn width(&self) -> u32 {
        self.x1 - self.x0
    }

    pub fn height(&self) -> u32 {
        self.y1 - self.y0
    }

    pub fn contains(&self, x: u32, y: u32) -> bool {
        (self.x0..self.x1).contains(&x) && (self.y0..self.y1).contains(&y)
    }

    /// Refuses a window that is empty or reaches outside a `width`×`height` image.
    pub fn check(&self, width: u32, height: u32) -> Result<(), String> {
        if self.x0 >= self.x1 || self.y0 >= self.y1 {
            return Err(format!(
                "the window {self} is empty (X0 < X1 and Y0 < Y1 are needed)"
            ));
        }
        if self.x1 > width || self.y1 > height {
            return Err(format!(
                "the window {self} reaches outside the {width}x{height} image"
            ));
        }
        Ok(())
    }

    /// The `k`-th of `n` bands of whole rows of a `width`×`height` image, `k` from 0: band
    /// `k` has rows `⌊k·height/n⌋ .. ⌊(k+1)·height/n⌋`, so the bands differ by at most one
    /// row and together hold every row once.
    pub fn tile(tile: Tile, width: u32, height: u32) -> Result<Window, String> {
        if tile.count > height {
            return Err(format!(
                "--tile {tile}: {} tiles of whole rows need an image at least {} rows high; it has {height}",
                tile.count, tile.count
            ));
        }
        let row = |k: u32| (k as u64 * height as u64 / tile.count as u64) as u32;
        Ok(Window {
            x0: 0,
            x1: width,
            y0: row(tile.index),
            y1: row(tile.index + 1),
        })
    }
}

impl fmt::Display for Window {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(f, "{},{},{},{}", self.x0, self.x1, self.y0, self.y1)
    }
}

impl std::str::FromStr for Window {
    type Err = String;

    /// `X0,X1,Y0,Y1`, as `--crop` takes it.
    fn from_str(s: &str) -> Result<Window, String> {
        let parts: Vec<&str> = s.split(',').map(str::trim).collect();
        let [x0, x1, y0, y1] = parts[..] else {
            return Err(format!(
                "expected X0,X1,Y0,Y1 such as 0,256,0,128, found `{s}`"
            ));
        };
        let n = |t: &str| {
            t.parse::<u32>()
                .map_err(|_| format!("expected a pixel coordinate, found `{t}`"))
        };
        let w = Window {
            x0: n(x0)?,
            x1: n(x1)?,
            y0: n(y0)?,
            y1: n(y1)?,
        };
        if w.x0 >= w.x1 || w.y0 >= w.y1 {
            return Err(format!(
                "the window {w} is empty (X0 < X1 and Y0 < Y1 are needed)"
            ));
        }
        Ok(w)
    }
}

/// `--tile K/N`: piece `index` (from 0) of `count`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Tile {
    pub index: u32,
    pub count: u32,
}

impl fmt::Display for Tile {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

impl std::str::FromStr for Tile {
    type Err = String;

    fn from_str(s: &str) -> Result<Tile, String> {
        let (k, n) = s
            .split_once('/')
            .ok_or_else(|| format!("expected K/N such as 0/8, found `{s}`"))?;
        let p = |t: &str| {
            t.trim()
                .parse::<u32>()
                .map_err(|_| format!("expected a whole number, found `{t}`"))
        };
        let (index, count) = (p(k)?, p(n)?);
        if count == 0 || index >= count {
            return Err(format!(
                "K/N needs N at least 1 and K from 0 to N-1, found `{s}`"
            ));
        }
        Ok(Tile { index, count })
    }
}

/// Checks that `windows` cover a `width`×`height` image exactly once: names the first
/// pixel covered twice or not at all.
pub fn check_cover(windows: &[Window], width: u32, height: u32) -> Result<(), String> {
    let mut count = vec![0u8; width as usize * height as usize];
    for w in windows {
        w.check(width, height)?;
        for y in w.y0..w.y1 {
            for x in w.x0..w.x1 {
                let c = &mut count[(y * width + x) as usize];
                if *c > 0 {
                    return Err(format!("pixel ({x}, {y}) is in two pieces"));
                }
                *c = 1;
            }
        }
    }
    match count.iter().position(|&c| c == 0) {
        Some(i) => Err(format!(
            "pixel ({}, {}) is in no piece",
            i as u32 % width,
            i as u32 / width
        )),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tiles_are_balanced_and_cover_the_image_once() {
        for (n, h) in [(1, 7), (7, 30), (7, 7), (3, 100), (16, 512)] {
            let bands: Vec<Window> = (0..n)
                .map(|k| Window::tile(Tile { index: k, count: n }, 9, h).unwrap())
                .collect();
            assert_eq!(check_cover(&bands, 9, h), Ok(()));
            let rows: Vec<u32> = bands.iter().map(Window::height).collect();
            let (lo, hi) = (rows.iter().min().unwrap(), rows.iter().max().unwrap());
            assert!(hi - lo <= 1, "{n} tiles of {h} rows: {rows:?}");
        }
        assert!(Window::tile(Tile { index: 0, count: 8 }, 9, 7).is_err());
    }

    #[test]
    fn gaps_and_overlaps_are_named() {
        let w = |s: &str| s.parse::<Window>().unwrap();
        let (a, b) = (w("0,4,0,2"), w("0,4,1,4"));
        let err = |ws: &[Window]| check_cover(ws, 4, 4).unwrap_err();
        assert_eq!(err(&[a, b]), "pixel (0, 1) is in two pieces");
        assert_eq!(err(&[w("0,4,2,4")]), "pixel (0, 0) is in no piece");
        assert!(err(&[w("0,5,0,4")]).contains("outside"));
    }

    #[test]
    fn crop_and_tile_values_parse_and_bad_ones_are_refused() {
        assert_eq!(
            "1,5,2,3".parse::<Window>(),
            Ok(Window {
                x0: 1,
                x1: 5,
                y0: 2,
                y1: 3
            })
        );
        for bad in ["1,5,2", "5,1,0,2", "0,1,2,2", "a,1,0,1", ""] {
            assert!(bad.parse::<Window>().is_err(), "{bad}");
        }
        assert_eq!("2/7".parse::<Tile>(), Ok(Tile { index: 2, count: 7 }));
        for bad in ["7/7", "0/0", "1", "-1/3", "x/3"] {
            assert!(bad.parse::<Tile>().is_err(), "{bad}");
        }
    }
}
