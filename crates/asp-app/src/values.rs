//! How a setting's value is written in a request: the closed sets and their names ([`Choice`],
//! also on the library's own enums), the values that are asp-app's own ([`Stability`],
//! [`Subassemblies`]), and the serde readers of the forms a value may take (a list as a list or
//! a comma-separated string, groups of names, a point as three numbers or `"x,y,z"`). The
//! settings table ([`crate::settings`]) names these readers; nothing here knows the table.

use serde::{Deserialize, Deserializer, Serialize};
use std::path::PathBuf;

/// A closed set of named values (`overlaps`, `stability`, `support`, `q_use`): the names with
/// one line of help each, for `--help`, Python's `Literal`s and error messages. The library's
/// own enums carry it where they exist (`asp_geom::OverlapPolicy`, `asp_geom::distmap::Support`,
/// `asp_search::QUse`), so a request holds the value the pipeline uses, with no mirror to match.
pub trait Choice: Sized + Copy + PartialEq + 'static {
    /// Every value with its name and its one-line help, in the order the docs list them.
    const CHOICES: &'static [(Self, &'static str, &'static str)];

    /// The value called `name`.
    fn parse(name: &str) -> Option<Self> {
        Self::CHOICES.iter().find(|(_, n, _)| *n == name).map(|(v, _, _)| *v)
    }

    /// The names, comma-separated (for messages).
    fn names() -> String {
        Self::CHOICES.iter().map(|(_, n, _)| *n).collect::<Vec<_>>().join(", ")
    }

    /// The value's name.
    fn name(self) -> &'static str {
        Self::CHOICES.iter().find(|(v, _, _)| *v == self).map(|(_, n, _)| *n).unwrap_or("?")
    }
}

/// Gives a closed set its names and help ([`Choice`]).
macro_rules! choice {
    ($name:ty { $($variant:ident = $text:expr => $help:literal,)+ }) => {
        impl Choice for $name {
            const CHOICES: &'static [(Self, &'static str, &'static str)] = &[$((<$name>::$variant, $text, $help),)+];
        }
    };
}

choice!(asp_geom::OverlapPolicy {
    Strict = "strict" => "an overlapping pair separates only along motions that enter no new material of each other (a dowel leaves along its axis, never sideways)",
    Lenient = "lenient" => "shrink one part of the pair in their tests; ignore pairs no shrinking separates",
    Error = "error" => "shrink small overlaps; stop with an error on pairs no shrinking separates",
});

/// The stability criterion of the feasibility search. The library's
/// [`crate::pipeline::StabilitySetting`] carries the physics threshold, a setting of its own
/// (`physics_threshold`), so the request names the criterion alone.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stability {
    /// Linked through contacts to a fixed part.
    Contact,
    /// Simulated under gravity.
    Physics,
}

choice!(Stability {
    Contact = "contact" => "every part linked through contacts to a fixed part",
    Physics = "physics" => "simulate what remains under gravity (rapier3d); unstable when a part moves more than `physics_threshold`",
});

choice!(asp_geom::distmap::Support {
    Below = "below" => "every part rests on a part or the floor directly beneath it (thesis 6.3.2)",
    ContactGraph = "contact" => "every part linked through contacts to a fixed part or the floor",
});

choice!(asp_search::QUse {
    Rollouts = asp_search::QUse::NAMES[0] => "ε-greedy rollouts (thesis: one evaluation per rollout step)",
    Expansions = asp_search::QUse::NAMES[1] => "the Q-values of each state the search adds order its expansions; rollouts stay random (one evaluation per node)",
    Both = asp_search::QUse::NAMES[2] => "ε-greedy rollouts and Q-ordered expansions",
    Priors = asp_search::QUse::NAMES[3] => "the Q-values of each state the search adds are PUCT priors (expansion order and a bonus in the tree policy), a greedy sequence on them seeds the local search; rollouts stay random (one evaluation per node, cached by state)",
    Seed = asp_search::QUse::NAMES[4] => "greedy sequences on the Q-values (their product and each objective's own) go to the front and seed the local search before the first episode; the search itself stays vanilla (one evaluation per step of those sequences, none after)",
});

/// A closed set's value in a request, by its [`Choice`] name (`#[serde(with = "...choice")]`).
pub(crate) mod choice {
    use super::Choice;
    use serde::{Deserialize, Deserializer, Serializer};

    pub fn serialize<S: Serializer, T: Choice>(v: &Option<T>, s: S) -> Result<S::Ok, S::Error> {
        match v {
            Some(v) => s.serialize_str(v.name()),
            None => s.serialize_none(),
        }
    }

    pub fn deserialize<'de, D: Deserializer<'de>, T: Choice>(d: D) -> Result<Option<T>, D::Error> {
        match Option::<String>::deserialize(d)? {
            None => Ok(None),
            Some(name) => {
                T::parse(&name).map(Some).ok_or_else(|| serde::de::Error::custom(format!("unknown value '{name}' (use {})", T::names())))
            }
        }
    }
}

/// The `subassemblies` setting: on, off, or the file's own product tree.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Subassemblies {
    /// Groups of parts the search finds leave together when no single part can (the default).
    On,
    /// Single parts only.
    Off,
    /// Each subassembly of the file's product tree planned on its own, then the level above with
    /// each as one unit.
    FromFile,
}

impl Subassemblies {
    /// The name of the tree mode, as the flag and the request spell it.
    pub const FROM_FILE: &'static str = "from-file";

    /// Whether groups may leave together (everything but `Off`).
    pub fn allowed(self) -> bool {
        self != Subassemblies::Off
    }
}

impl Serialize for Subassemblies {
    fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        match self {
            Subassemblies::On => s.serialize_bool(true),
            Subassemblies::Off => s.serialize_bool(false),
            Subassemblies::FromFile => s.serialize_str(Subassemblies::FROM_FILE),
        }
    }
}

impl<'de> Deserialize<'de> for Subassemblies {
    fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        #[derive(Deserialize)]
        #[serde(untagged)]
        enum Raw {
            Switch(bool),
            Mode(String),
        }
        match Raw::deserialize(d) {
            Ok(Raw::Switch(true)) => Ok(Subassemblies::On),
            Ok(Raw::Switch(false)) => Ok(Subassemblies::Off),
            Ok(Raw::Mode(m)) if m == Subassemblies::FROM_FILE => Ok(Subassemblies::FromFile),
            _ => Err(serde::de::Error::custom("must be true, false or 'from-file'")),
        }
    }
}

/// [`Subassemblies`], optional.
pub(crate) fn subassemblies<'de, D: Deserializer<'de>>(d: D) -> std::result::Result<Option<Subassemblies>, D::Error> {
    Option::<Subassemblies>::deserialize(d)
}

/// A comma-separated string or a list of strings, as a list (blank names dropped).
pub(crate) fn names<'de, D: Deserializer<'de>>(d: D) -> std::result::Result<Option<Vec<String>>, D::Error> {
    #[derive(Deserialize)]
    #[serde(untagged)]
    enum OneOrMany {
        One(String),
        Many(Vec<String>),
    }
    let split = |s: &str| s.split(',').map(str::trim).filter(|n| !n.is_empty()).map(String::from).collect::<Vec<_>>();
    Ok(
        match Option::<OneOrMany>::deserialize(d)
            .map_err(|_| serde::de::Error::custom("must be a comma-separated string or a list of strings"))?
        {
            None => None,
            Some(OneOrMany::One(s)) => Some(split(&s)),
            Some(OneOrMany::Many(v)) => Some(v.iter().flat_map(|s| split(s)).collect()),
        },
    )
}

/// Groups of names: a list whose items are each a comma-separated string or a list of names, or
/// one comma-separated string (one group).
pub(crate) fn groups<'de, D: Deserializer<'de>>(d: D) -> std::result::Result<Vec<Vec<String>>, D::Error> {
    #[derive(Deserialize)]
    #[serde(untagged)]
    enum Group {
        Text(String),
        Names(Vec<String>),
    }
    #[derive(Deserialize)]
    #[serde(untagged)]
    enum Groups {
        One(String),
        Many(Vec<Group>),
    }
    let split = |s: &str| s.split(',').map(str::trim).filter(|n| !n.is_empty()).map(String::from).collect::<Vec<_>>();
    let bad = || serde::de::Error::custom("must be a list of groups, each a comma-separated string or a list of part names");
    Ok(match Option::<Groups>::deserialize(d).map_err(|_| bad())? {
        None => Vec::new(),
        Some(Groups::One(s)) => vec![split(&s)],
        Some(Groups::Many(v)) => v
            .into_iter()
            .map(|g| match g {
                Group::Text(s) => split(&s),
                Group::Names(names) => names.into_iter().map(|n| n.trim().to_string()).filter(|n| !n.is_empty()).collect(),
            })
            .collect(),
    })
}

/// [`names`] as paths.
pub(crate) fn paths<'de, D: Deserializer<'de>>(d: D) -> std::result::Result<Option<Vec<PathBuf>>, D::Error> {
    Ok(names(d)?.map(|v| v.into_iter().map(PathBuf::from).collect()))
}

/// Three numbers, as a list or as `"x,y,z"`.
pub(crate) fn point<'de, D: Deserializer<'de>>(d: D) -> std::result::Result<Option<[f64; 3]>, D::Error> {
    #[derive(Deserialize)]
    #[serde(untagged)]
    enum Point {
        Text(String),
        List(Vec<f64>),
    }
    let bad = || serde::de::Error::custom("must be three finite numbers x,y,z");
    let v: Vec<f64> = match Option::<Point>::deserialize(d).map_err(|_| bad())? {
        None => return Ok(None),
        Some(Point::List(v)) => v,
        Some(Point::Text(s)) => s.split(',').map(|x| x.trim().parse::<f64>()).collect::<std::result::Result<_, _>>().map_err(|_| bad())?,
    };
    match v[..] {
        [x, y, z] if v.iter().all(|c| c.is_finite()) => Ok(Some([x, y, z])),
        _ => Err(bad()),
    }
}
