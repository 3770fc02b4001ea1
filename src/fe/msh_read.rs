//! Reading Gmsh `.msh` files, format 4.1, ASCII and binary, into a [`Mesh`].
//!
//! The `mshio` crate parses the `$MeshFormat`, `$Entities`, `$Nodes` and `$Elements` sections
//! in both encodings. Two things it does not give are done here:
//! - `$PhysicalNames` (the group names) is not parsed by mshio; the section is plain text in
//!   both encodings and precedes the binary sections, so it is read from the bytes before
//!   `$Entities`.
//! - When the node tags of a file are contiguous (max − min + 1 = count), mshio drops them and
//!   leaves the caller to assume that the nodes appear in tag order. Gmsh does not promise that,
//!   so [`node_tags_in_file_order`] reads the tag lists of the `$Nodes` section again (a light
//!   scan that skips the coordinates) instead of guessing.
//!
//! mshio still has `unimplemented!`/`expect` calls on some malformed headers (its own TODOs),
//! so the `$MeshFormat` line is checked first, and any panic left inside mshio is turned into
//! an error rather than taking the program down.
//!
//! Supported element types: points, 2-node lines, 3-node triangles, 4-node quadrangles,
//! 8-node hexahedra; any other type in the file is an error naming it. Physical groups without
//! a name in `$PhysicalNames` are named `group_<dim>_<tag>`.

use std::collections::HashMap;
use std::path::Path;

use mshio::{MshFile, MshParserError};

use super::mesh::{Element, ElementKind, Entity, Mesh, Node, PhysicalGroup};

/// Errors of reading a `.msh` file; each names the file.
#[derive(Debug, thiserror::Error)]
pub enum MshReadError {
    /// The file could not be read.
    #[error("{file}: cannot read: {source}")]
    Io {
        /// File.
        file: String,
        /// Cause.
        source: std::io::Error,
    },
    /// mshio rejected the file.
    #[error("{file}: not a valid Gmsh 4.1 mesh (near byte {offset}, line {line}): {reason}")]
    Parse {
        /// File.
        file: String,
        /// Byte offset where parsing failed.
        offset: usize,
        /// Line number of that offset (meaningful for ASCII files).
        line: usize,
        /// mshio's explanation, innermost last.
        reason: String,
    },
    /// The file parses but its content is not usable.
    #[error("{file}: {reason}")]
    Content {
        /// File.
        file: String,
        /// What is wrong.
        reason: String,
    },
}

/// Reads a Gmsh 4.1 mesh (ASCII or binary).
pub fn read_msh(path: &Path) -> Result<Mesh, MshReadError> {
    let file = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|source| MshReadError::Io {
        file: file.clone(),
        source,
    })?;
    read_msh_bytes(&bytes, &file)
}

/// Reads a Gmsh 4.1 mesh from memory; `source` names it in messages.
pub fn read_msh_bytes(bytes: &[u8], source: &str) -> Result<Mesh, MshReadError> {
    let content = |reason: String| MshReadError::Content {
        file: source.to_string(),
        reason,
    };
    check_header(bytes).map_err(|reason| MshReadError::Parse {
        file: source.to_string(),
        offset: 0,
        line: 2,
        reason,
    })?;
    // mshio still has `unimplemented!`/`expect` calls on unusual input (its own TODOs); the
    // header check above avoids the known ones, and a panic left inside it becomes an error.
    let parsed = std::panic::catch_unwind(|| {
        mshio::parse_msh_bytes(bytes).map_err(|e| parse_error(bytes, source, &e))
    });
    let msh = match parsed {
        Ok(result) => result?,
        Err(_) => {
            return Err(content(
                "the Gmsh parser (mshio) failed on this file; check that it is a Gmsh 4.1 mesh"
                    .into(),
            ))
        }
    };
    let names = physical_names(bytes).map_err(content)?;

    // Entities (synthesised from the element blocks when the file has no $Entities).
    let mut entities = Vec::new();
    if let Some(ents) = &msh.data.entities {
        entities.extend(
            ents.points
                .iter()
                .map(|p| entity(0, p.tag, &p.physical_tags)),
        );
        entities.extend(
            ents.curves
                .iter()
                .map(|c| entity(1, c.tag, &c.physical_tags)),
        );
        entities.extend(
            ents.surfaces
                .iter()
                .map(|s| entity(2, s.tag, &s.physical_tags)),
        );
        entities.extend(
            ents.volumes
                .iter()
                .map(|v| entity(3, v.tag, &v.physical_tags)),
        );
    }

    let nodes = read_nodes(&msh, bytes).map_err(content)?;
    let index_of: HashMap<u64, usize> = nodes.iter().enumerate().map(|(i, n)| (n.id, i)).collect();
    if index_of.len() != nodes.len() {
        return Err(content("a node tag appears twice in $Nodes".into()));
    }

    let mut elements = Vec::new();
    if let Some(blocks) = &msh.data.elements {
        for block in &blocks.element_blocks {
            let code = block.element_type as i32;
            let dim = usize::try_from(block.entity_dim).map_err(|_| {
                content(format!("element block with dimension {}", block.entity_dim))
            })?;
            let Some(kind) = ElementKind::from_gmsh_type(code) else {
                let first = block.elements.first().map(|e| e.element_tag).unwrap_or(0);
                return Err(content(format!(
                    "element {first} (entity dim {dim}, tag {}) has Gmsh type {code} \
                     ({:?}), not supported: use points, 2-node lines, 3-node triangles, \
                     4-node quadrangles or 8-node hexahedra",
                    block.entity_tag, block.element_type
                )));
            };
            if msh.data.entities.is_none()
                && !entities
                    .iter()
                    .any(|e: &Entity| e.dim == dim && e.tag == block.entity_tag)
            {
                entities.push(entity(dim, block.entity_tag, &[]));
            }
            for element in &block.elements {
                let nodes = element
                    .nodes
                    .iter()
                    .map(|tag| {
                        index_of.get(tag).copied().ok_or_else(|| {
                            content(format!(
                                "element {} refers to node {tag}, which is not in $Nodes",
                                element.element_tag
                            ))
                        })
                    })
                    .collect::<Result<Vec<usize>, _>>()?;
                if nodes.len() != kind.node_count() {
                    return Err(content(format!(
                        "element {} ({}) has {} nodes",
                        element.element_tag,
                        kind.name(),
                        nodes.len()
                    )));
                }
                elements.push(Element {
                    id: element.element_tag,
                    kind,
                    nodes,
                    entity_dim: dim,
                    entity_tag: block.entity_tag,
                });
            }
        }
    }

    // Physical groups: named ones from $PhysicalNames, then any tag used by an entity.
    let mut groups: Vec<PhysicalGroup> = names
        .iter()
        .map(|(dim, tag, name)| PhysicalGroup {
            name: name.clone(),
            dim: *dim,
            tag: *tag,
        })
        .collect();
    for e in &entities {
        for &tag in &e.physical_tags {
            if !groups.iter().any(|g| g.dim == e.dim && g.tag == tag) {
                groups.push(PhysicalGroup {
                    name: format!("group_{}_{tag}", e.dim),
                    dim: e.dim,
                    tag,
                });
            }
        }
    }

    let mesh = Mesh {
        source: source.to_string(),
        nodes,
        elements,
        entities,
        groups,
    };
    mesh.validate().map_err(|e| content(e.to_string()))?;
    Ok(mesh)
}

fn entity(dim: usize, tag: i32, physical_tags: &[i32]) -> Entity {
    Entity {
        dim,
        tag,
        physical_tags: physical_tags.iter().map(|t| t.abs()).collect(),
    }
}

/// Checks the `$MeshFormat` line before mshio sees it: mshio panics on a size_t size it has
/// no parser for and on an unparsable number there.
fn check_header(bytes: &[u8]) -> Result<(), String> {
    let text_end = bytes.len().min(256);
    let head = String::from_utf8_lossy(&bytes[..text_end]);
    let mut lines = head.lines().map(str::trim);
    if lines.next() != Some("$MeshFormat") {
        return Err("the file does not start with $MeshFormat".into());
    }
    let format = lines.next().unwrap_or("");
    let words: Vec<&str> = format.split_whitespace().collect();
    let valid = words.len() == 3
        && (words[1] == "0" || words[1] == "1")
        && (words[2] == "4" || words[2] == "8");
    if !valid {
        return Err(format!(
            "$MeshFormat line `{format}`: expected `4.1 0 8` (ASCII) or `4.1 1 8` (binary)"
        ));
    }
    Ok(())
}

/// Error with the failing offset/line and mshio's context chain (without its hex dump).
fn parse_error(bytes: &[u8], file: &str, error: &MshParserError<&[u8]>) -> MshReadError {
    let remaining = error
        .backtrace
        .first()
        .map(|(rest, _)| rest.len())
        .unwrap_or(0);
    let offset = bytes.len().saturating_sub(remaining);
    let line = bytes[..offset].iter().filter(|&&b| b == b'\n').count() + 1;
    let reason = error
        .backtrace
        .iter()
        .rev()
        .filter(|(_, kind)| !kind.is_nom_error())
        .map(|(_, kind)| kind.to_string().trim_end_matches('.').to_string())
        .collect::<Vec<_>>()
        .join(": ");
    MshReadError::Parse {
        file: file.to_string(),
        offset,
        line,
        reason: if reason.is_empty() {
            "unexpected content".into()
        } else {
            reason
        },
    }
}

/// Position of a section start tag at the beginning of a line, searched in `bytes[..limit]`.
fn find_section(bytes: &[u8], tag: &str, limit: usize) -> Option<usize> {
    let tag = tag.as_bytes();
    let limit = limit.min(bytes.len());
    (0..limit).find(|&i| {
        (i == 0 || bytes[i - 1] == b'\n')
            && bytes[i..].starts_with(tag)
            && matches!(bytes.get(i + tag.len()), None | Some(b'\n' | b'\r' | b' '))
    })
}

/// The `$PhysicalNames` entries (dimension, tag, name); empty if the section is absent.
fn physical_names(bytes: &[u8]) -> Result<Vec<(usize, i32, String)>, String> {
    // Binary data only follows $Entities/$Nodes, so the text sections come before them.
    let limit = [
        find_section(bytes, "$Entities", bytes.len()),
        find_section(bytes, "$Nodes", bytes.len()),
    ]
    .into_iter()
    .flatten()
    .min()
    .unwrap_or(bytes.len());
    let Some(start) = find_section(bytes, "$PhysicalNames", limit) else {
        return Ok(Vec::new());
    };
    let end = find_section(bytes, "$EndPhysicalNames", limit)
        .ok_or("$PhysicalNames has no $EndPhysicalNames")?;
    let text =
        std::str::from_utf8(&bytes[start..end]).map_err(|_| "$PhysicalNames is not UTF-8 text")?;
    let mut lines = text.lines().skip(1).filter(|l| !l.trim().is_empty());
    let count: usize = lines
        .next()
        .and_then(|l| l.trim().parse().ok())
        .ok_or("$PhysicalNames: missing the number of names")?;
    let mut names = Vec::with_capacity(count);
    for line in lines.by_ref().take(count) {
        let bad = || format!("$PhysicalNames: cannot read `{}`", line.trim());
        let mut words = line.trim().splitn(3, char::is_whitespace);
        let dim: usize = words.next().and_then(|w| w.parse().ok()).ok_or_else(bad)?;
        let tag: i32 = words.next().and_then(|w| w.parse().ok()).ok_or_else(bad)?;
        let quoted = words.next().map(str::trim).ok_or_else(bad)?;
        let name = quoted
            .strip_prefix('"')
            .and_then(|q| q.strip_suffix('"'))
            .ok_or_else(bad)?;
        if dim > 3 {
            return Err(bad());
        }
        names.push((dim, tag, name.to_string()));
    }
    if names.len() != count {
        return Err(format!(
            "$PhysicalNames announces {count} names but holds {}",
            names.len()
        ));
    }
    Ok(names)
}

/// Nodes with their tags, in file order.
fn read_nodes(msh: &MshFile<u64, i32, f64>, bytes: &[u8]) -> Result<Vec<Node>, String> {
    let Some(section) = &msh.data.nodes else {
        return Ok(Vec::new());
    };
    let dense_tags = if section.node_blocks.iter().any(|b| b.node_tags.is_none()) {
        Some(node_tags_in_file_order(msh, bytes)?)
    } else {
        None
    };
    let mut nodes = Vec::new();
    for block in &section.node_blocks {
        let tags: Vec<u64> = match &block.node_tags {
            Some(map) => {
                let mut tags = vec![0u64; block.nodes.len()];
                for (&tag, &i) in map {
                    if i < tags.len() {
                        tags[i] = tag;
                    }
                }
                tags
            }
            None => {
                let all = dense_tags.as_ref().ok_or("node tags missing")?;
                let start = nodes.len();
                all.get(start..start + block.nodes.len())
                    .ok_or("$Nodes holds fewer tags than nodes")?
                    .to_vec()
            }
        };
        for (node, tag) in block.nodes.iter().zip(tags) {
            nodes.push(Node {
                id: tag,
                coords: [node.x, node.y, node.z],
            });
        }
    }
    Ok(nodes)
}

/// The node tags of the `$Nodes` section in file order, read from the bytes (ASCII or binary
/// as the header says). Only called on a file mshio has parsed, so the layout is known good.
pub fn node_tags_in_file_order(
    msh: &MshFile<u64, i32, f64>,
    bytes: &[u8],
) -> Result<Vec<u64>, String> {
    let start = find_section(bytes, "$Nodes", bytes.len()).ok_or("no $Nodes section")?;
    let body_start = bytes[start..]
        .iter()
        .position(|&b| b == b'\n')
        .map(|p| start + p + 1)
        .ok_or("$Nodes line not terminated")?;
    let body = &bytes[body_start..];
    if msh.header.file_type == 0 {
        ascii_node_tags(body)
    } else {
        binary_node_tags(
            body,
            msh.header.size_t_size,
            binary_is_little_endian(bytes)?,
        )
    }
}

/// Byte order of a binary file: `$MeshFormat` holds, after its text line, the integer 1
/// written in the file's byte order.
fn binary_is_little_endian(bytes: &[u8]) -> Result<bool, String> {
    let start = find_section(bytes, "$MeshFormat", bytes.len()).ok_or("no $MeshFormat")?;
    let mut pos = start;
    for _ in 0..2 {
        pos += bytes[pos..]
            .iter()
            .position(|&b| b == b'\n')
            .ok_or("$MeshFormat cut short")?
            + 1;
    }
    match bytes.get(pos..pos + 4) {
        Some([1, 0, 0, 0]) => Ok(true),
        Some([0, 0, 0, 1]) => Ok(false),
        _ => Err("$MeshFormat: cannot read the byte-order marker".into()),
    }
}

fn ascii_node_tags(body: &[u8]) -> Result<Vec<u64>, String> {
    let text_end = find_section(body, "$EndNodes", body.len()).unwrap_or(body.len());
    let text = std::str::from_utf8(&body[..text_end]).map_err(|_| "$Nodes is not text")?;
    let mut words = text.split_ascii_whitespace();
    let mut next = |what: &str, skip: usize| -> Result<u64, String> {
        for _ in 0..skip {
            words.next().ok_or("$Nodes: coordinates cut short")?;
        }
        words
            .next()
            .and_then(|w| w.parse::<u64>().ok())
            .ok_or_else(|| format!("$Nodes: cannot read {what}"))
    };
    let blocks = next("the number of blocks", 0)?;
    let count = next("the number of nodes", 0)?;
    next("the min tag", 0)?;
    next("the max tag", 0)?;
    let mut tags = Vec::with_capacity(count as usize);
    // Coordinates (3 per node, more when parametric, which mshio rejects anyway) are skipped
    // before the next block's header.
    let mut skip = 0usize;
    for _ in 0..blocks {
        next("a block dimension", skip)?;
        next("a block entity tag", 0)?;
        let parametric = next("a block parametric flag", 0)?;
        let n = next("a block node count", 0)?;
        for _ in 0..n {
            tags.push(next("a node tag", 0)?);
        }
        skip = n as usize * (3 + parametric as usize);
    }
    Ok(tags)
}

fn binary_node_tags(body: &[u8], size_t: usize, little: bool) -> Result<Vec<u64>, String> {
    let mut pos = 0usize;
    let mut take = |len: usize| -> Result<&[u8], String> {
        let slice = body
            .get(pos..pos + len)
            .ok_or("$Nodes: binary data cut short")?;
        pos += len;
        Ok(slice)
    };
    let uint = |b: &[u8]| -> u64 {
        let mut v = 0u64;
        if little {
            for (k, &byte) in b.iter().enumerate() {
                v |= (byte as u64) << (8 * k);
            }
        } else {
            for &byte in b {
                v = (v << 8) | byte as u64;
            }
        }
        v
    };
    if size_t != 4 && size_t != 8 {
        return Err(format!("unsupported size_t size {size_t}"));
    }
    let blocks = uint(take(size_t)?);
    let count = uint(take(size_t)?);
    take(2 * size_t)?; // min and max tag
    let mut tags = Vec::with_capacity(count as usize);
    for _ in 0..blocks {
        take(4 * 2)?; // entity dim, entity tag
        let parametric = uint(take(4)?);
        let n = uint(take(size_t)?) as usize;
        for _ in 0..n {
            tags.push(uint(take(size_t)?));
        }
        take(n * 8 * (3 + parametric as usize))?;
    }
    Ok(tags)
}
