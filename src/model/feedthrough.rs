//! Names in a [`Feedthrough::Some`] list: checked against the declared variables at compile time, and
//! expanded to FMI scalar names for every consumer (GUID, catalogue, FMI 3.0 dependencies).
//!
//! A name is either an FMI scalar name (`torque_cmd_x`) or the stem of a vector row of the
//! declaration table (`torque_cmd` for `torque_cmd_x/_y/_z`, `inertia` for `inertia_xx/_yy/_zz`, `q`
//! for `q_w/_x/_y/_z`), which stands for all its components. An exact name wins over a stem.
//!
//! [`ModelEntry::of`](super::ModelEntry::of) evaluates [`Checked::FEEDTHROUGH`] for every exported
//! model, so a list naming an output or input that the table does not declare stops the build with a
//! message naming the model, the name and the valid names:
//!
//! ```compile_fail
//! use spacecraft_fmus::export::*;
//! declare_variables! {
//!     pub struct LeakyVars {
//!         0 => u: Real = 0.0, Input, "", "Input";
//!         1 => y: Real = 0.0, Output, "", "Output";
//!     }
//! }
//! #[derive(Clone, Serialize, Deserialize)]
//! pub struct Leaky;
//! impl Model for Leaky {
//!     type Vars = LeakyVars;
//!     const EVOLVING: &'static [&'static str] = &[];
//!     const INFO: ModelInfo = ModelInfo {
//!         name: "Leaky",
//!         feedthrough: Feedthrough::Some(&[("y", &["uu"])]), // not an input: compile error
//!         ..ModelInfo::DEFAULT
//!     };
//!     fn initialize(_: &mut LeakyVars, _: &Experiment) -> Result<Self, String> { Ok(Leaky) }
//!     fn outputs(&self, _: &mut LeakyVars, _: f64) -> ModelResult { Ok(()) }
//! }
//! const ENTRY: ModelEntry = ModelEntry::of::<Leaky>();
//! ```

use std::marker::PhantomData;

use super::contract::{Model, Variables};
use crate::catalogue::decl::{Causality, Feedthrough, VarDecl};
use crate::text::same_str;

/// Component suffixes of the vector kinds of `declare_variables!` (`Vec3`, `Diag3`, `Quat`).
const SUFFIXES: [&str; 7] = ["x", "y", "z", "w", "xx", "yy", "zz"];

/// Whether `name` is `<stem>_<suffix>` with a vector component suffix.
const fn is_component_of(stem: &str, name: &str) -> bool {
    let (s, n) = (stem.as_bytes(), name.as_bytes());
    if n.len() < s.len() + 2 || n[s.len()] != b'_' {
        return false;
    }
    let mut i = 0;
    while i < s.len() {
        if s[i] != n[i] {
            return false;
        }
        i += 1;
    }
    let tail = n.split_at(s.len() + 1).1;
    let mut k = 0;
    while k < SUFFIXES.len() {
        let suffix = SUFFIXES[k].as_bytes();
        if suffix.len() == tail.len() {
            let mut j = 0;
            while j < tail.len() && tail[j] == suffix[j] {
                j += 1;
            }
            if j == tail.len() {
                return true;
            }
        }
        k += 1;
    }
    false
}

/// Whether the declared variable `d` is meant by the feed-through name `name` in the table `decls`:
/// its exact name, or (when no variable has that exact name) a component of the stem `name`.
pub const fn names(decls: &[VarDecl], name: &str, d: &VarDecl) -> bool {
    if same_str(name, d.name) {
        return true;
    }
    let mut i = 0;
    while i < decls.len() {
        if same_str(decls[i].name, name) {
            return false;
        }
        i += 1;
    }
    is_component_of(name, d.name)
}

const fn same_causality(a: Causality, b: Causality) -> bool {
    a as u8 == b as u8
}

/// Number of variables of `causality` that `name` stands for (as [`names`] decides, with the search for
/// an exact name done once: linear in the table, so long lists on large tables stay cheap at compile time).
const fn count(decls: &[VarDecl], name: &str, causality: Causality) -> usize {
    let mut exact = false;
    let mut i = 0;
    while i < decls.len() {
        if same_str(decls[i].name, name) {
            exact = true;
        }
        i += 1;
    }
    let mut n = 0;
    i = 0;
    while i < decls.len() {
        let d = &decls[i];
        let meant = if exact {
            same_str(name, d.name)
        } else {
            is_component_of(name, d.name)
        };
        if same_causality(d.causality, causality) && meant {
            n += 1;
        }
        i += 1;
    }
    n
}

/// A message assembled at compile time (a const panic takes a `&str`, not a `format!`).
struct Message {
    buf: [u8; 1536],
    len: usize,
}

impl Message {
    const fn new() -> Self {
        Message { buf: [0; 1536], len: 0 }
    }

    /// Appends `s`, cut (at a character boundary) when the buffer is full.
    const fn push(&mut self, s: &str) {
        let b = s.as_bytes();
        let mut i = 0;
        while i < b.len() && self.len < self.buf.len() - 4 {
            self.buf[self.len] = b[i];
            self.len += 1;
            i += 1;
        }
        if i < b.len() {
            while self.len > 0 && self.buf[self.len] & 0xC0 == 0x80 {
                self.len -= 1;
            }
            self.buf[self.len] = b'.';
            self.buf[self.len + 1] = b'.';
            self.buf[self.len + 2] = b'.';
            self.len += 3;
        }
    }

    /// Appends the names of the variables of `causality`, comma-separated.
    const fn push_names(&mut self, decls: &[VarDecl], causality: Causality) {
        let mut first = true;
        let mut i = 0;
        while i < decls.len() {
            if same_causality(decls[i].causality, causality) {
                if !first {
                    self.push(", ");
                }
                self.push(decls[i].name);
                first = false;
            }
            i += 1;
        }
        if first {
            self.push("(none)");
        }
    }

    const fn as_str(&self) -> &str {
        match std::str::from_utf8(self.buf.split_at(self.len).0) {
            Ok(s) => s,
            Err(_) => "feed-through list names an undeclared variable",
        }
    }
}

/// Panics (a compile error when evaluated in a constant) unless every output and input a feed-through
/// list names is a declared output or input, or the stem of one; the message lists the valid names.
pub const fn check(model: &str, feedthrough: Feedthrough, decls: &[VarDecl]) {
    let Feedthrough::Some(list) = feedthrough else {
        return;
    };
    let mut i = 0;
    while i < list.len() {
        let (output, inputs) = list[i];
        if count(decls, output, Causality::Output) == 0 {
            fail(model, "output", output, decls, Causality::Output);
        }
        let mut j = 0;
        while j < inputs.len() {
            if count(decls, inputs[j], Causality::Input) == 0 {
                fail(model, "input", inputs[j], decls, Causality::Input);
            }
            j += 1;
        }
        i += 1;
    }
}

const fn fail(model: &str, what: &str, name: &str, decls: &[VarDecl], causality: Causality) {
    let mut m = Message::new();
    m.push(model);
    m.push(": feed-through ");
    m.push(what);
    m.push(" `");
    m.push(name);
    m.push("` is not an ");
    m.push(what);
    m.push(" of the model (nor the stem of a vector ");
    m.push(what);
    m.push("); its ");
    m.push(what);
    m.push("s are: ");
    m.push_names(decls, causality);
    panic!("{}", m.as_str());
}

/// The compile-time check of one model's feed-through list, evaluated by
/// [`ModelEntry::of`](super::ModelEntry::of).
pub struct Checked<M>(PhantomData<M>);

impl<M: Model> Checked<M> {
    pub const FEEDTHROUGH: () = check(M::INFO.name, M::INFO.feedthrough, <M::Vars as Variables>::DECLS);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{scalar_list, ModelEntry};
    use crate::models::attitude::control::PdController;
    use crate::models::attitude::plant::AttitudePlant;

    #[test]
    fn stems_name_the_components_of_vector_rows_only() {
        assert!(is_component_of("torque_cmd", "torque_cmd_x"));
        assert!(is_component_of("inertia", "inertia_zz"));
        assert!(is_component_of("q", "q_w"));
        assert!(!is_component_of("torque", "torque_cmd_x"));
        assert!(!is_component_of("q", "q_ref_w"));
        assert!(!is_component_of("q", "q"));
        assert!(!is_component_of("q", "q_"));
    }

    #[test]
    fn a_vector_stem_expands_to_its_components_and_scalar_lists_are_unchanged() {
        let plant = ModelEntry::of::<AttitudePlant>();
        let Feedthrough::Some(given) = plant.info.feedthrough else {
            panic!("the plant lists its feed-through")
        };
        let scalar = scalar_list(&plant).unwrap();
        // the plant's list mixes stems ("torque_applied", "b_eci") and scalar names ("dipole_x", "m_cmd_x")
        assert_eq!(given[0], ("torque_applied", &["torque_cmd", "m_cmd", "b_eci"][..]));
        let applied = [
            "torque_cmd_x",
            "torque_cmd_y",
            "torque_cmd_z",
            "m_cmd_x",
            "m_cmd_y",
            "m_cmd_z",
            "b_eci_x",
            "b_eci_y",
            "b_eci_z",
        ];
        for (k, axis) in ["torque_applied_x", "torque_applied_y", "torque_applied_z"]
            .into_iter()
            .enumerate()
        {
            assert_eq!(scalar[k], (axis, applied.to_vec()));
        }
        assert_eq!(
            scalar[3],
            ("dipole_x", vec!["m_cmd_x", "b_eci_x", "b_eci_y", "b_eci_z"])
        );
        assert_eq!(scalar.len(), 3 + 3 + 3 + 3 * 7);

        static INFO: crate::model::ModelInfo = crate::model::ModelInfo {
            feedthrough: Feedthrough::Some(&[("torque_cmd", &["q", "w_x", "q"])]),
            ..crate::model::ModelInfo::DEFAULT
        };
        let pd = ModelEntry {
            info: &INFO,
            ..ModelEntry::of::<PdController>()
        };
        let list = scalar_list(&pd).unwrap();
        let inputs = vec!["q_w", "q_x", "q_y", "q_z", "w_x"];
        assert_eq!(
            list,
            vec![
                ("torque_cmd_x", inputs.clone()),
                ("torque_cmd_y", inputs.clone()),
                ("torque_cmd_z", inputs)
            ]
        );
    }

    #[test]
    fn the_check_names_the_unknown_variable_and_lists_the_valid_ones() {
        let pd = ModelEntry::of::<PdController>();
        check("Pd", Feedthrough::Some(&[("torque_cmd", &["q_ref", "w"])]), pd.decls);
        let err = std::panic::catch_unwind(|| {
            check("Pd", Feedthrough::Some(&[("torque", &["q"])]), pd.decls);
        })
        .unwrap_err();
        let text = err.downcast_ref::<String>().cloned().unwrap_or_default();
        assert!(
            text.starts_with("Pd: feed-through output `torque` is not an output"),
            "{text}"
        );
        assert!(text.contains("torque_cmd_x, torque_cmd_y, torque_cmd_z"), "{text}");
        let err = std::panic::catch_unwind(|| {
            check("Pd", Feedthrough::Some(&[("torque_cmd", &["torque_cmd"])]), pd.decls);
        })
        .unwrap_err();
        let text = err.downcast_ref::<String>().cloned().unwrap_or_default();
        assert!(
            text.contains("input `torque_cmd` is not an input") && text.contains("q_w, q_x"),
            "{text}"
        );
    }
}
