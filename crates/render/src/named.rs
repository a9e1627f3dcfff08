//! Closed sets of named choices (strategy kinds, heuristics, samplers, light-sampling modes,
//! ...): one table per set gives each choice its name and a line of help, and everything that
//! reads or lists a name follows from it: parsing (`FromStr`, serde through
//! `TryFrom<String>`), printing (`Display`), the command line's accepted values and their
//! help, and the error that lists the valid names. A new choice is one row of its table.

/// One choice of a set: its value, the name files and the command line use, and a line of
/// help.
#[derive(Clone, Copy, Debug)]
pub struct Choice<T: 'static> {
    /// The value.
    pub value: T,
    /// The name the command line, scene and experiment files use.
    pub name: &'static str,
    /// One line saying what it is, for `--help` and the README.
    pub help: &'static str,
}

/// A closed set of named values; see the module documentation.
pub trait Named: Sized + Copy + PartialEq + 'static {
    /// What a value of the set is called in messages ("sampler").
    const WHAT: &'static str;
    /// Every choice, in the order lists show them.
    const CHOICES: &'static [Choice<Self>];
    /// Short forms in strategy labels where they differ from the name.
    const SHORT: &'static [(Self, &'static str)] = &[];

    /// The name of `self`.
    fn name(self) -> &'static str {
        Self::choice(self).name
    }

    /// The short form of `self` in strategy labels (its name unless `SHORT` gives one).
    fn short(self) -> &'static str {
        Self::SHORT
            .iter()
            .find(|(v, _)| *v == self)
            .map_or_else(|| self.name(), |(_, s)| s)
    }

    /// The help line of `self`.
    fn help(self) -> &'static str {
        Self::choice(self).help
    }

    /// The table row of `self` (every value has one; a missing row is a bug the registry
    /// tests catch).
    fn choice(self) -> &'static Choice<Self> {
        Self::CHOICES
            .iter()
            .find(|c| c.value == self)
            .expect("every value of a Named set has a row in CHOICES")
    }

    /// Every value, in table order.
    fn all() -> Vec<Self> {
        Self::CHOICES.iter().map(|c| c.value).collect()
    }

    /// The value named `s`, or an error naming the set and listing every valid name.
    fn from_name(s: &str) -> Result<Self, String> {
        let t = s.trim();
        Self::CHOICES
            .iter()
            .find(|c| c.name == t)
            .map(|c| c.value)
            .ok_or_else(|| {
                format!(
                    "unknown {} '{t}': expected {}",
                    Self::WHAT,
                    one_of(Self::CHOICES.iter().map(|c| c.name))
                )
            })
    }
}

/// "a", "a or b", "one of a, b, c".
pub fn one_of<'a>(names: impl Iterator<Item = &'a str>) -> String {
    let v: Vec<&str> = names.collect();
    match v.len() {
        0 => "nothing".into(),
        1 => v[0].into(),
        2 => format!("{} or {}", v[0], v[1]),
        _ => format!("one of {}", v.join(", ")),
    }
}

/// `FromStr`, `Display` and `TryFrom<String>` (serde's `try_from = "String"`) of a
/// [`Named`] type, all through its table.
#[macro_export]
macro_rules! named_impls {
    ($t:ty) => {
        impl std::str::FromStr for $t {
            type Err = String;
            fn from_str(s: &str) -> Result<Self, String> {
                <$t as $crate::named::Named>::from_name(s)
            }
        }
        impl std::fmt::Display for $t {
            fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str(<$t as $crate::named::Named>::name(*self))
            }
        }
        impl TryFrom<String> for $t {
            type Error = String;
            fn try_from(s: String) -> Result<Self, String> {
                <$t as $crate::named::Named>::from_name(&s)
            }
        }
    };
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Clone, Copy, Debug, PartialEq)]
    enum Fruit {
        Apple,
        Pear,
        Fig,
    }

    impl Named for Fruit {
        const WHAT: &'static str = "fruit";
        const CHOICES: &'static [Choice<Self>] = &[
            Choice {
                value: Fruit::Apple,
                name: "apple",
                help: "red",
            },
            Choice {
                value: Fruit::Pear,
                name: "pear",
                help: "green",
            },
            Choice {
                value: Fruit::Fig,
                name: "fig",
                help: "purple",
            },
        ];
    }
    named_impls!(Fruit);

    #[test]
    fn names_round_trip_and_errors_list_the_valid_names() {
        for f in Fruit::all() {
            assert_eq!(f.name().parse::<Fruit>(), Ok(f));
            assert_eq!(f.to_string(), f.name());
        }
        assert_eq!(Fruit::Pear.help(), "green");
        assert_eq!(
            "kiwi".parse::<Fruit>(),
            Err("unknown fruit 'kiwi': expected one of apple, pear, fig".into())
        );
        assert_eq!(one_of(["a", "b"].into_iter()), "a or b");
    }
}
