//! The query modules of Open L-systems and their fixed signatures.
//!
//! Owns: which `?` modules exist, which leading parameters the environment fills
//! (outputs) and how many pass-through parameters each needs at least. A query in
//! a predecessor is written with its outputs first and then the pass-through
//! parameters; in an axiom or successor only the pass-through parameters are
//! written (the outputs start at 0 until the environment answers).

/// Which question a query module asks: what the environment matches on when
/// it answers (names are for the checker and messages only).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum QueryKind {
    /// `?P`: the turtle's position.
    Position,
    /// `?H`: the turtle's heading.
    Heading,
    /// `?U`: the turtle's up vector.
    Up,
    /// `?L`: the turtle's left vector.
    Left,
    /// `?D_L`: the distance to the closest link edge.
    DistanceLink,
    /// `?D_G`: the distance to the closest guide edge.
    DistanceGuide,
    /// `?D_A`: the distance to the closest element.
    DistanceElement,
    /// `?N_L`: the distance ahead to the next link edge.
    AheadLink,
    /// `?N_G`: the distance ahead to the next guide edge.
    AheadGuide,
    /// `?N_A`: the distance ahead to the next guide edge or element.
    AheadElement,
    /// `?X`: whether the next element collides.
    Collision,
}

#[derive(Clone, Copy, Debug)]
pub struct Query {
    pub name: &'static str,
    pub kind: QueryKind,
    /// Names of the outputs, in order.
    pub outputs: &'static [&'static str],
    /// Pass-through parameters the environment reads (at least this many).
    pub inputs: &'static [&'static str],
    pub doc: &'static str,
}

pub const QUERIES: &[Query] = &[
    Query {
        name: "?P",
        kind: QueryKind::Position,
        outputs: &["x", "y", "z"],
        inputs: &[],
        doc: "turtle position",
    },
    Query {
        name: "?H",
        kind: QueryKind::Heading,
        outputs: &["hx", "hy", "hz"],
        inputs: &[],
        doc: "turtle heading (unit vector)",
    },
    Query {
        name: "?U",
        kind: QueryKind::Up,
        outputs: &["ux", "uy", "uz"],
        inputs: &[],
        doc: "turtle up vector (unit vector)",
    },
    Query {
        name: "?L",
        kind: QueryKind::Left,
        outputs: &["lx", "ly", "lz"],
        inputs: &[],
        doc: "turtle left vector (unit vector)",
    },
    Query {
        name: "?D_L",
        kind: QueryKind::DistanceLink,
        outputs: &["found", "d", "beta", "id"],
        inputs: &[],
        doc: "distance d and turning angle beta to the closest link edge of the guide",
    },
    Query {
        name: "?D_G",
        kind: QueryKind::DistanceGuide,
        outputs: &["found", "d", "beta", "id"],
        inputs: &[],
        doc: "distance d and turning angle beta to the closest guide edge",
    },
    Query {
        name: "?D_A",
        kind: QueryKind::DistanceElement,
        outputs: &["found", "d", "beta", "id"],
        inputs: &[],
        doc: "distance d and turning angle beta to the closest element in the guide",
    },
    Query {
        name: "?N_L",
        kind: QueryKind::AheadLink,
        outputs: &["found", "d", "id"],
        inputs: &[],
        doc: "distance along the heading to the next link edge",
    },
    Query {
        name: "?N_G",
        kind: QueryKind::AheadGuide,
        outputs: &["found", "d", "id"],
        inputs: &[],
        doc: "distance along the heading to the next guide edge",
    },
    Query {
        name: "?N_A",
        kind: QueryKind::AheadElement,
        outputs: &["found", "d", "id"],
        inputs: &[],
        doc: "distance along the heading to the next guide edge or element",
    },
    Query {
        name: "?X",
        kind: QueryKind::Collision,
        outputs: &["found", "id"],
        inputs: &["delta"],
        doc: "whether the next element of length delta collides with a guide edge, link or element",
    },
];

impl QueryKind {
    /// Whether the turtle alone answers it (in every run, not only in scenes).
    pub fn is_turtle(self) -> bool {
        matches!(
            self,
            QueryKind::Position | QueryKind::Heading | QueryKind::Up | QueryKind::Left
        )
    }
}

pub fn lookup(name: &str) -> Option<&'static Query> {
    QUERIES.iter().find(|q| q.name == name)
}

impl Query {
    /// The form written in a predecessor, e.g. `?X(found, id, delta, …)`.
    pub fn signature(&self) -> String {
        let mut parts: Vec<&str> = self.outputs.to_vec();
        parts.extend_from_slice(self.inputs);
        parts.push("…");
        format!("{}({})", self.name, parts.join(", "))
    }
}
