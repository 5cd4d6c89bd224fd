//! A face of a solid's boundary: a triangle or a bilinear quadrilateral.

/// A face of a solid's boundary (a face set's member, a contact surface's facet, a
/// traction's support): three or four corner nodes, numbered counter-clockwise seen
/// from outside, so that its normal points out of the body.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Face {
    nodes: [usize; 4],
    corners: u8,
}

impl Face {
    /// The triangle with corners `n`.
    pub fn triangle(n: [usize; 3]) -> Face {
        Face {
            nodes: [n[0], n[1], n[2], 0],
            corners: 3,
        }
    }

    /// The quadrilateral with corners `n`.
    pub fn quadrilateral(n: [usize; 4]) -> Face {
        Face {
            nodes: n,
            corners: 4,
        }
    }

    /// The face with the corners `c`: a triangle for three, a quadrilateral for four,
    /// `None` otherwise.
    pub fn from_corners(c: &[usize]) -> Option<Face> {
        match *c {
            [a, b, d] => Some(Face::triangle([a, b, d])),
            [a, b, d, e] => Some(Face::quadrilateral([a, b, d, e])),
            _ => None,
        }
    }

    /// The corner nodes, in order.
    pub fn corners(&self) -> &[usize] {
        &self.nodes[..self.corners as usize]
    }

    /// The corner nodes, to renumber or reorder in place.
    pub fn corners_mut(&mut self) -> &mut [usize] {
        &mut self.nodes[..self.corners as usize]
    }

    /// Whether the face is a triangle.
    pub fn is_triangle(&self) -> bool {
        self.corners == 3
    }

    /// The same face with every node renumbered by `f`.
    pub fn map(mut self, f: impl Fn(usize) -> usize) -> Face {
        for n in self.corners_mut() {
            *n = f(*n);
        }
        self
    }
}

impl std::ops::Index<usize> for Face {
    type Output = usize;

    /// Corner `k` (panics beyond the corners).
    fn index(&self, k: usize) -> &usize {
        &self.corners()[k]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_face_has_its_corners_and_no_more() {
        let t = Face::triangle([4, 7, 9]);
        assert_eq!(t.corners(), &[4, 7, 9]);
        assert!(t.is_triangle());
        assert_eq!(t.map(|n| n + 1).corners(), &[5, 8, 10]);
        let q = Face::from_corners(&[1, 2, 3, 4]).unwrap();
        assert!(!q.is_triangle() && q[3] == 4);
        assert_eq!(Face::from_corners(&[1, 2]), None);
        assert!(std::panic::catch_unwind(|| t[3]).is_err());
    }
}
