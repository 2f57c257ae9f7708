//! Argument types shared by the subcommands: the command line's names for
//! the libraries' choices (the libraries know no command line).

use clap::ValueEnum;

/// `--space`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Space {
    /// Bottle pose: mouth position (m) and orientation (unit quaternion).
    Cartesian,
    /// The arm's seven joint angles (rad).
    Joint,
}

impl From<Space> for primo_learn::pour::skill::Space {
    fn from(s: Space) -> Self {
        match s {
            Space::Cartesian => primo_learn::pour::skill::Space::Cartesian,
            Space::Joint => primo_learn::pour::skill::Space::Joint,
        }
    }
}

/// `--glass`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Glass {
    /// 7 cm opening.
    Normal,
    /// Half the diameter, as in the paper's second experiment.
    Small,
}

impl From<Glass> for primo_sim::cell::GlassKind {
    fn from(g: Glass) -> Self {
        match g {
            Glass::Normal => primo_sim::cell::GlassKind::Normal,
            Glass::Small => primo_sim::cell::GlassKind::Small,
        }
    }
}

/// `--method`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Method {
    /// The paper's error learning with golden-section search on the query.
    Golden,
    /// Error learning that also uses the error's magnitude (Illinois
    /// regula falsi), with the same bracket guarantee.
    Illinois,
    /// Error learning with a gain learned from the roll-outs (Broyden's
    /// secant update of the paper's eq. 10).
    Secant,
    /// The paper's eq. 10 with a fixed gain (--gain).
    FixedGain,
    /// The paper's eq. 11: eq. 10 weighted by e^(-ε²).
    WeightedGain,
    /// PoWER over the extended parameter set `[q̂, Δθ]`.
    Power,
    /// PoWER whose query is learned from the error (eq. 10, --gain) while
    /// it explores Δθ.
    PowerEl,
}

impl From<Method> for primo_learn::algorithm::Algorithm {
    fn from(m: Method) -> Self {
        use primo_learn::algorithm::Algorithm;
        match m {
            Method::Golden => Algorithm::Golden,
            Method::Illinois => Algorithm::Illinois,
            Method::Secant => Algorithm::Secant,
            Method::FixedGain => Algorithm::FixedGain,
            Method::WeightedGain => Algorithm::WeightedGain,
            Method::Power => Algorithm::Power,
            Method::PowerEl => Algorithm::PowerEl,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `--method` spells each learner as files and messages do: every
    /// learner but secant-goals, which learns a task file's goals.
    #[test]
    fn each_method_is_spelled_as_its_learners_key() {
        use primo_learn::algorithm::Algorithm;
        let mut spelled: Vec<Algorithm> = Vec::new();
        for m in Method::value_variants() {
            let name = m.to_possible_value().map(|v| v.get_name().to_string());
            let algorithm: Algorithm = (*m).into();
            assert_eq!(name.as_deref(), Some(algorithm.key()));
            spelled.push(algorithm);
        }
        let unspelled: Vec<Algorithm> = (Algorithm::ALL.into_iter())
            .filter(|a| !spelled.contains(a))
            .collect();
        assert_eq!(unspelled, [Algorithm::SecantGoals]);
    }
}
