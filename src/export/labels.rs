//! Where a chart's text labels go: each label beside its point at the first of a ring of offsets whose box
//! overlaps no box already placed (labels and the chart's own text) and stays inside the plot; a label with no
//! free place is left out, never drawn over another. The PNG and HTML charts share it, so a label that is
//! drawn never overlaps another by construction (the browser test measures the HTML's boxes too).

/// An axis-aligned box in pixels: left, top, right, bottom.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rect {
    pub x0: f64,
    pub y0: f64,
    pub x1: f64,
    pub y1: f64,
}

impl Rect {
    pub fn overlaps(&self, o: &Rect) -> bool {
        self.x0 < o.x1 && o.x0 < self.x1 && self.y0 < o.y1 && o.y0 < self.y1
    }

    /// The point of the box nearest to `p`, where a leader line from `p` ends.
    pub fn nearest(&self, (x, y): (f64, f64)) -> (f64, f64) {
        (x.clamp(self.x0, self.x1), y.clamp(self.y0, self.y1))
    }

    /// Whether a label at this box needs a leader line to tell which point it names (it lies beyond the
    /// first ring).
    pub fn far_from(&self, p: (f64, f64)) -> bool {
        let (x, y) = self.nearest(p);
        (x - p.0).hypot(y - p.1) > RINGS[0] * 1.5 + 1.0
    }

    fn inside(&self, o: &Rect) -> bool {
        self.x0 >= o.x0 && self.x1 <= o.x1 && self.y0 >= o.y0 && self.y1 <= o.y1
    }
}

/// Gaps between a point and its label tried in turn, in pixels.
const RINGS: [f64; 4] = [7.0, 18.0, 32.0, 50.0];

/// The boxes placed so far within a plot's bounds.
pub struct Placer {
    bounds: Rect,
    placed: Vec<Rect>,
}

impl Placer {
    pub fn new(bounds: Rect) -> Self {
        Placer { bounds, placed: Vec::new() }
    }

    /// Marks a box as taken (a point's marker, a legend) without placing a label there.
    pub fn occupy(&mut self, r: Rect) {
        self.placed.push(r);
    }

    /// A `w` x `h` label for the point at (px, py): right of it, then left, above, below, each at growing
    /// gaps; None where every place is taken or outside the bounds.
    pub fn place(&mut self, (px, py): (f64, f64), w: f64, h: f64) -> Option<Rect> {
        let at = |x0: f64, y0: f64| Rect { x0, y0, x1: x0 + w, y1: y0 + h };
        let found = RINGS
            .iter()
            .flat_map(|&g| {
                [
                    at(px + g, py - h - g / 2.0),
                    at(px + g, py + g / 2.0),
                    at(px - g - w, py - h - g / 2.0),
                    at(px - g - w, py + g / 2.0),
                    at(px + g, py - h / 2.0),
                    at(px - g - w, py - h / 2.0),
                    at(px - w / 2.0, py - g - h),
                    at(px - w / 2.0, py + g),
                ]
            })
            .find(|r| r.inside(&self.bounds) && !self.placed.iter().any(|o| o.overlaps(r)))?;
        self.placed.push(found);
        Some(found)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_of_crowded_points_never_overlap_and_stay_inside() {
        let bounds = Rect { x0: 0.0, y0: 0.0, x1: 400.0, y1: 300.0 };
        let mut p = Placer::new(bounds);
        let mut got = Vec::new();
        // 60 points in a 40 x 40 px cluster: most cannot be labelled, none that is overlaps another.
        for k in 0..60 {
            let at = (180.0 + (k % 8) as f64 * 5.0, 130.0 + (k / 8) as f64 * 5.0);
            got.extend(p.place(at, 90.0, 13.0));
        }
        assert!(got.len() > 8 && got.len() < 60, "{} placed", got.len());
        for (i, a) in got.iter().enumerate() {
            assert!(a.inside(&bounds));
            assert!(got[..i].iter().all(|b| !a.overlaps(b)), "{a:?}");
        }
    }
}
