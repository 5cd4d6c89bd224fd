//! The Gmsh MSH 4.1 file format, ASCII and binary: the sections a mesh needs
//! (`$MeshFormat`, `$PhysicalNames`, `$Entities`, `$Nodes`, `$Elements`) read into
//! plain blocks exactly as the file lists them; other sections are skipped.
//!
//! Nothing is inferred from the order of tags: every node block keeps the tags it
//! lists beside the coordinates it lists, in the same order, whether the tags ascend,
//! descend, are sparse or repeat (the mesh builder in [`super::gmsh`] decides what a
//! repetition means). Errors say the section and, in ASCII files, the line.

use std::collections::HashMap;

/// A block of nodes of one entity, as listed.
pub struct NodeBlock {
    /// Dimension of the entity (0 point, 1 curve, 2 surface, 3 volume).
    pub entity_dim: i32,
    /// Tag of the entity.
    pub entity_tag: i32,
    /// The node tags in the order the block lists them.
    pub tags: Vec<u64>,
    /// The coordinates `x, y, z`, one per tag in the same order.
    pub xyz: Vec<[f64; 3]>,
}

/// A block of elements of one type on one entity, as listed.
pub struct ElementBlock {
    /// Dimension of the entity.
    pub entity_dim: i32,
    /// Tag of the entity.
    pub entity_tag: i32,
    /// Gmsh element type number (1 two-node line, 2 three-node triangle, ...).
    pub element_type: i32,
    /// Nodes per element of this type.
    pub nodes_per_element: usize,
    /// The element tags in the order listed.
    pub tags: Vec<u64>,
    /// The node tags of every element, `nodes_per_element` each.
    pub nodes: Vec<u64>,
}

/// The parts of a MSH 4.1 file a mesh is built from.
#[derive(Default)]
pub struct MshFile {
    /// `$PhysicalNames`: `(dim, tag, name)` in the order listed.
    pub physical_names: Vec<(i32, i32, String)>,
    /// `$Entities`: the physical tags of each `(dim, tag)` entity.
    pub entity_groups: HashMap<(i32, i32), Vec<i32>>,
    /// `$Nodes`: the blocks in the order listed.
    pub node_blocks: Vec<NodeBlock>,
    /// `$Elements`: the blocks in the order listed.
    pub element_blocks: Vec<ElementBlock>,
    /// Whether the `$Nodes` section was present.
    pub has_nodes: bool,
    /// Whether the `$Elements` section was present.
    pub has_elements: bool,
}

/// Nodes of a Gmsh element type, or `None` for a type number Gmsh does not define.
pub fn nodes_per_element(element_type: i32) -> Option<usize> {
    Some(match element_type {
        1 => 2,
        2 => 3,
        3 => 4,
        4 => 4,
        5 => 8,
        6 => 6,
        7 => 5,
        8 => 3,
        9 => 6,
        10 => 9,
        11 => 10,
        12 => 27,
        13 => 18,
        14 => 14,
        15 => 1,
        16 => 8,
        17 => 20,
        18 => 15,
        19 => 13,
        20 => 9,
        21 => 10,
        22 => 12,
        23 => 15,
        24 => 15,
        25 => 21,
        26 => 4,
        27 => 5,
        28 => 6,
        29 => 20,
        30 => 35,
        31 => 56,
        92 => 64,
        93 => 125,
        _ => return None,
    })
}

/// Reads the bytes of a MSH 4.1 file.
pub fn parse(bytes: &[u8]) -> Result<MshFile, String> {
    let mut c = Cursor {
        bytes,
        pos: 0,
        binary: false,
        section: "$MeshFormat",
    };
    let mut file = MshFile::default();
    let mut seen_format = false;
    while let Some(name) = c.next_section()? {
        c.section = name;
        match name {
            "$MeshFormat" => {
                c.mesh_format()?;
                seen_format = true;
            }
            _ if !seen_format => {
                return Err(format!(
                    "the file does not start with $MeshFormat (found {name} first)"
                ))
            }
            "$PhysicalNames" => file.physical_names = c.physical_names()?,
            "$Entities" => file.entity_groups = c.entities()?,
            "$Nodes" => {
                file.node_blocks = c.nodes()?;
                file.has_nodes = true;
            }
            "$Elements" => {
                file.element_blocks = c.elements()?;
                file.has_elements = true;
            }
            _ => {
                c.skip_to_end(name)?;
                continue;
            }
        }
        c.end_of(name)?;
    }
    if !seen_format {
        return Err("not a MSH file: no $MeshFormat section".into());
    }
    Ok(file)
}

/// A position in the file and how to read numbers there.
struct Cursor<'a> {
    bytes: &'a [u8],
    pos: usize,
    binary: bool,
    section: &'static str,
}

impl<'a> Cursor<'a> {
    /// Where the cursor is, for messages: the section and, in ASCII, the line.
    fn here(&self) -> String {
        if self.binary && self.section != "$PhysicalNames" && self.section != "$MeshFormat" {
            format!("in {} at byte {}", self.section, self.pos)
        } else {
            let line = 1 + self.bytes[..self.pos.min(self.bytes.len())]
                .iter()
                .filter(|&&b| b == b'\n')
                .count();
            format!("in {} at line {line}", self.section)
        }
    }

    fn error(&self, what: impl std::fmt::Display) -> String {
        format!("{}: {what}", self.here())
    }

    fn skip_space(&mut self) {
        while self.pos < self.bytes.len() && self.bytes[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
    }

    /// The next whitespace-separated word.
    fn word(&mut self) -> Option<&'a str> {
        self.skip_space();
        let start = self.pos;
        while self.pos < self.bytes.len() && !self.bytes[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
        (self.pos > start).then(|| std::str::from_utf8(&self.bytes[start..self.pos]).ok())?
    }

    /// The next section header, or `None` at the end of the file.
    fn next_section(&mut self) -> Result<Option<&'static str>, String> {
        let Some(w) = self.word() else {
            return Ok(None);
        };
        const KNOWN: [&str; 5] = [
            "$MeshFormat",
            "$PhysicalNames",
            "$Entities",
            "$Nodes",
            "$Elements",
        ];
        if let Some(k) = KNOWN.iter().find(|k| **k == w) {
            // The header's line ends with one newline; binary data starts after it.
            if self.bytes.get(self.pos) == Some(&b'\r') {
                self.pos += 1;
            }
            if self.bytes.get(self.pos) == Some(&b'\n') {
                self.pos += 1;
            }
            return Ok(Some(k));
        }
        if w.starts_with('$') && !w.starts_with("$End") {
            self.section = "another section";
            // Skipped: remembered only for the search of its end.
            let end = format!("$End{}", &w[1..]);
            return match find(&self.bytes[self.pos..], end.as_bytes()) {
                Some(at) => {
                    self.pos += at + end.len();
                    self.next_section()
                }
                None => Err(format!("section {w} has no {end}")),
            };
        }
        Err(self.error(format!("expected a section header, found `{w}`")))
    }

    fn skip_to_end(&mut self, name: &str) -> Result<(), String> {
        let end = format!("$End{}", &name[1..]);
        let at = find(&self.bytes[self.pos..], end.as_bytes())
            .ok_or_else(|| format!("section {name} has no {end}"))?;
        self.pos += at + end.len();
        Ok(())
    }

    fn end_of(&mut self, name: &str) -> Result<(), String> {
        let end = format!("$End{}", &name[1..]);
        match self.word() {
            Some(w) if w == end => Ok(()),
            Some(w) => Err(self.error(format!(
                "expected {end}, found `{w}` (more entries than the section declares?)"
            ))),
            None => Err(format!("the file ends inside {name} (no {end})")),
        }
    }

    fn mesh_format(&mut self) -> Result<(), String> {
        let version = self.word().ok_or_else(|| self.error("no version"))?;
        if version != "4.1" {
            return Err(format!(
                "MSH version {version} is not supported: save the mesh as version 4.1 \
                 (Gmsh: -format msh41, or Mesh.MshFileVersion = 4.1)"
            ));
        }
        let kind = self.word().ok_or_else(|| self.error("no file type"))?;
        let size = self.word().ok_or_else(|| self.error("no data size"))?;
        if size != "8" {
            return Err(self.error(format!(
                "data size {size} is not supported (8-byte size_t expected)"
            )));
        }
        match kind {
            "0" => self.binary = false,
            "1" => {
                // One newline, then the integer 1 in the file's byte order.
                self.pos += 1;
                let one = self.raw::<4>()?;
                if i32::from_le_bytes(one) != 1 {
                    return Err(
                        "a binary file in big-endian byte order is not supported".to_string()
                    );
                }
                self.binary = true;
            }
            other => return Err(self.error(format!("file type {other} is neither 0 nor 1"))),
        }
        Ok(())
    }

    fn raw<const N: usize>(&mut self) -> Result<[u8; N], String> {
        let end = self.pos + N;
        let b = self
            .bytes
            .get(self.pos..end)
            .ok_or_else(|| self.error("the file ends in the middle of a number"))?;
        self.pos = end;
        Ok(b.try_into().expect("N bytes"))
    }

    fn ascii<T: std::str::FromStr>(&mut self, what: &str) -> Result<T, String> {
        let w = self
            .word()
            .ok_or_else(|| self.error(format!("the file ends where {what} was expected")))?;
        w.parse()
            .map_err(|_| self.error(format!("expected {what}, found `{w}`")))
    }

    /// An `int` (4 bytes in binary).
    fn int(&mut self, what: &str) -> Result<i32, String> {
        if self.binary {
            Ok(i32::from_le_bytes(self.raw::<4>()?))
        } else {
            self.ascii(what)
        }
    }

    /// A `size_t` (8 bytes in binary).
    fn size(&mut self, what: &str) -> Result<u64, String> {
        if self.binary {
            Ok(u64::from_le_bytes(self.raw::<8>()?))
        } else {
            self.ascii(what)
        }
    }

    /// A count of items of at least `numbers` numbers each, bounded by what the rest
    /// of the file can hold (a number takes at least 4 bytes in binary, 2 in ASCII),
    /// so that a corrupt count is an error, not an allocation of its size.
    fn count(&mut self, what: &str, numbers: usize) -> Result<usize, String> {
        let n = self.size(what)?;
        let per = numbers.max(1) * if self.binary { 4 } else { 2 };
        let room = self.bytes.len().saturating_sub(self.pos) / per;
        if n > room as u64 {
            return Err(self.error(format!(
                "{what} is {n}, more than the rest of the file can hold"
            )));
        }
        Ok(n as usize)
    }

    fn double(&mut self, what: &str) -> Result<f64, String> {
        if self.binary {
            Ok(f64::from_le_bytes(self.raw::<8>()?))
        } else {
            self.ascii(what)
        }
    }

    fn physical_names(&mut self) -> Result<Vec<(i32, i32, String)>, String> {
        // Always text, even in binary files.
        let binary = std::mem::replace(&mut self.binary, false);
        let n = self.count("the number of physical names", 3)?;
        let mut out = Vec::with_capacity(n);
        for _ in 0..n {
            let dim = self.ascii("a physical dimension")?;
            let tag = self.ascii("a physical tag")?;
            self.skip_space();
            let line_end = self.bytes[self.pos..]
                .iter()
                .position(|&b| b == b'\n')
                .map_or(self.bytes.len(), |e| self.pos + e);
            let name = String::from_utf8_lossy(&self.bytes[self.pos..line_end])
                .trim()
                .to_string();
            let quoted = name.len() >= 2 && name.starts_with('"') && name.ends_with('"');
            if !quoted {
                return Err(self.error(format!("physical name `{name}` is not in double quotes")));
            }
            self.pos = line_end;
            out.push((dim, tag, name[1..name.len() - 1].to_string()));
        }
        self.binary = binary;
        Ok(out)
    }

    fn entities(&mut self) -> Result<HashMap<(i32, i32), Vec<i32>>, String> {
        let mut counts = [0usize; 4];
        for (d, c) in counts.iter_mut().enumerate() {
            *c = self.count(&format!("the number of {}-dimensional entities", d), 5)?;
        }
        let mut out = HashMap::new();
        for (dim, &n) in counts.iter().enumerate() {
            for _ in 0..n {
                let tag = self.int("an entity tag")?;
                let n_coords = if dim == 0 { 3 } else { 6 };
                for _ in 0..n_coords {
                    self.double("an entity coordinate")?;
                }
                let n_phys = self.count("the number of physical tags", 1)?;
                let groups = (0..n_phys)
                    .map(|_| self.int("a physical tag"))
                    .collect::<Result<Vec<_>, _>>()?;
                if dim > 0 {
                    let n_bound = self.count("the number of bounding entities", 1)?;
                    for _ in 0..n_bound {
                        self.int("a bounding entity tag")?;
                    }
                }
                if out.insert((dim as i32, tag), groups).is_some() {
                    return Err(self.error(format!(
                        "the {dim}-dimensional entity {tag} is listed twice"
                    )));
                }
            }
        }
        Ok(out)
    }

    fn nodes(&mut self) -> Result<Vec<NodeBlock>, String> {
        let n_blocks = self.count("the number of node blocks", 4)?;
        let n_nodes = self.count("the number of nodes", 4)?;
        let _min_tag = self.size("the smallest node tag")?;
        let _max_tag = self.size("the largest node tag")?;
        let mut blocks = Vec::with_capacity(n_blocks);
        let mut total = 0usize;
        for _ in 0..n_blocks {
            let entity_dim = self.int("an entity dimension")?;
            let entity_tag = self.int("an entity tag")?;
            let parametric = self.int("the parametric flag")?;
            let n = self.count("the number of nodes in a block", 4)?;
            if !(0..=3).contains(&entity_dim) {
                return Err(self.error(format!("entity dimension {entity_dim} is not 0-3")));
            }
            let tags = (0..n)
                .map(|_| self.size("a node tag"))
                .collect::<Result<Vec<_>, _>>()?;
            let extra = if parametric != 0 {
                entity_dim as usize
            } else {
                0
            };
            let mut xyz = Vec::with_capacity(n);
            for _ in 0..n {
                let x = self.double("an x coordinate")?;
                let y = self.double("a y coordinate")?;
                let z = self.double("a z coordinate")?;
                for _ in 0..extra {
                    self.double("a parametric coordinate")?;
                }
                xyz.push([x, y, z]);
            }
            total += n;
            blocks.push(NodeBlock {
                entity_dim,
                entity_tag,
                tags,
                xyz,
            });
        }
        if total != n_nodes {
            return Err(format!(
                "$Nodes declares {n_nodes} nodes, its blocks list {total}"
            ));
        }
        Ok(blocks)
    }

    fn elements(&mut self) -> Result<Vec<ElementBlock>, String> {
        let n_blocks = self.count("the number of element blocks", 4)?;
        let n_elements = self.count("the number of elements", 2)?;
        let _min_tag = self.size("the smallest element tag")?;
        let _max_tag = self.size("the largest element tag")?;
        let mut blocks = Vec::with_capacity(n_blocks);
        let mut total = 0usize;
        for _ in 0..n_blocks {
            let entity_dim = self.int("an entity dimension")?;
            let entity_tag = self.int("an entity tag")?;
            let element_type = self.int("an element type")?;
            let per = nodes_per_element(element_type)
                .ok_or_else(|| self.error(format!("element type {element_type} is unknown")))?;
            let n = self.count("the number of elements in a block", per + 1)?;
            let mut tags = Vec::with_capacity(n);
            let mut nodes = Vec::with_capacity(n * per);
            for _ in 0..n {
                tags.push(self.size("an element tag")?);
                for _ in 0..per {
                    nodes.push(self.size("a node tag of an element")?);
                }
            }
            total += n;
            blocks.push(ElementBlock {
                entity_dim,
                entity_tag,
                element_type,
                nodes_per_element: per,
                tags,
                nodes,
            });
        }
        if total != n_elements {
            return Err(format!(
                "$Elements declares {n_elements} elements, its blocks list {total}"
            ));
        }
        Ok(blocks)
    }
}

fn find(hay: &[u8], needle: &[u8]) -> Option<usize> {
    hay.windows(needle.len()).position(|w| w == needle)
}

#[cfg(test)]
mod tests {
    use super::*;

    const ASCII: &str = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 3 1 3\n2 1 0 3\n3\n1\n2\n0 0 0\n1 0 0\n0 1 0\n$EndNodes\n$Elements\n1 1 7 7\n2 1 2 1\n7 3 1 2\n$EndElements\n";

    /// The ASCII file above written in the binary form.
    fn binary() -> Vec<u8> {
        let mut b = b"$MeshFormat\n4.1 1 8\n".to_vec();
        b.extend(1i32.to_le_bytes());
        b.extend(b"\n$EndMeshFormat\n$Nodes\n");
        for x in [1u64, 3, 1, 3] {
            b.extend(x.to_le_bytes());
        }
        for x in [2i32, 1, 0] {
            b.extend(x.to_le_bytes());
        }
        b.extend(3u64.to_le_bytes());
        for t in [3u64, 1, 2] {
            b.extend(t.to_le_bytes());
        }
        for x in [0.0f64, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0] {
            b.extend(x.to_le_bytes());
        }
        b.extend(b"\n$EndNodes\n$Elements\n");
        for x in [1u64, 1, 7, 7] {
            b.extend(x.to_le_bytes());
        }
        for x in [2i32, 1, 2] {
            b.extend(x.to_le_bytes());
        }
        b.extend(1u64.to_le_bytes());
        for x in [7u64, 3, 1, 2] {
            b.extend(x.to_le_bytes());
        }
        b.extend(b"\n$EndElements\n");
        b
    }

    #[test]
    fn ascii_and_binary_give_the_same_blocks_in_the_listed_order() {
        for bytes in [ASCII.as_bytes().to_vec(), binary()] {
            let f = parse(&bytes).unwrap();
            assert_eq!(f.node_blocks.len(), 1);
            assert_eq!(f.node_blocks[0].tags, vec![3, 1, 2]);
            assert_eq!(f.node_blocks[0].xyz[1], [1.0, 0.0, 0.0]);
            assert_eq!(f.element_blocks[0].tags, vec![7]);
            assert_eq!(f.element_blocks[0].nodes, vec![3, 1, 2]);
            assert_eq!(f.element_blocks[0].nodes_per_element, 3);
        }
    }

    #[test]
    fn errors_say_the_section_and_the_line() {
        let bad = ASCII.replace("1 0 0\n", "1 zero 0\n");
        let e = parse(bad.as_bytes()).err().unwrap();
        assert!(e.contains("in $Nodes at line 11:"), "{e}");
        assert!(e.contains("expected a y coordinate, found `zero`"), "{e}");
        let short = ASCII.replace("1 3 1 3\n", "1 4 1 3\n");
        let e = parse(short.as_bytes()).err().unwrap();
        assert!(e.contains("declares 4 nodes, its blocks list 3"), "{e}");
        let huge = ASCII.replace("2 1 0 3\n", "2 1 0 99999999999\n");
        let e = parse(huge.as_bytes()).err().unwrap();
        assert!(e.contains("more than the rest of the file can hold"), "{e}");
        let old = ASCII.replace("4.1 0 8", "2.2 0 8");
        assert!(parse(old.as_bytes()).err().unwrap().contains("version 2.2"));
        let truncated = &binary()[..90];
        assert!(parse(truncated).is_err());
    }

    #[test]
    fn unknown_sections_are_skipped() {
        let with = ASCII.replace(
            "$Nodes",
            "$Comments\nanything $Nodes-free here\n$EndComments\n$Nodes",
        );
        let f = parse(with.as_bytes()).unwrap();
        assert_eq!(f.node_blocks[0].tags, vec![3, 1, 2]);
    }
}
