//! The `<ModelStructure>` dependency lists of a model, as 1-based ScalarVariable indices in the FMI 2.0
//! order (declared variables, then the continuous states, then their derivatives): outputs from the
//! feed-through table, derivatives from the states' `depends_on` lists, initial unknowns from both and
//! the states' `starting_from` lists. The FMI 3.0 description translates the same lists to value
//! references, so the two versions never disagree.

use spacecraft_fmus::catalogue::{
    Causality, FeedthroughDescription as Feedthrough, Initial, ModelDescription, StateDescription, VariableDescription,
};

/// 1-based indices (position in ModelVariables) of the inputs the output `out` depends on directly.
pub fn output_dependencies(m: &ModelDescription, out: &VariableDescription) -> Vec<usize> {
    let index_of = |name: &str| {
        m.variables
            .iter()
            .position(|d| d.name == name)
            .unwrap_or_else(|| panic!("{}: feedthrough names unknown variable {name}", m.name))
            + 1
    };
    let inputs = || {
        m.variables
            .iter()
            .enumerate()
            .filter(|(_, d)| d.causality == Causality::Input)
            .map(|(i, _)| i + 1)
    };
    match &m.feedthrough {
        Feedthrough::None => vec![],
        Feedthrough::AllInputs => inputs().collect(),
        Feedthrough::Some(list) => list
            .iter()
            .filter(|(o, _)| *o == out.name)
            .flat_map(|(_, ins)| ins.iter().map(|n| index_of(n)))
            .collect(),
    }
}

/// `<InitialUnknowns>` with their dependencies, from the same declaration as `<Outputs>`.
///
/// FMI 2.0 lists as initial unknowns the outputs with `initial` approx/calculated and the calculated
/// parameters, each in ScalarVariable order; their knowns in Initialization Mode are the inputs and the
/// variables with `initial="exact"` (our parameters). An output depends on the inputs it feeds through
/// (the model's `Feedthrough`, the same list as in `<Outputs>`) and on the parameters; a calculated
/// parameter depends on the parameters only. The parameter part is a superset (the declarations do not
/// say which parameter feeds which output); parameters are never connected, so it cannot create a loop.
pub fn initial_unknowns(m: &ModelDescription) -> Vec<(usize, Vec<usize>)> {
    let params: Vec<usize> = m
        .variables
        .iter()
        .enumerate()
        .filter(|(_, d)| d.causality == Causality::Parameter && d.initial() == Some(Initial::Exact))
        .map(|(i, _)| i + 1)
        .collect();
    m.variables
        .iter()
        .enumerate()
        .filter_map(|(i, d)| {
            let inputs = match d.causality {
                // its feed-through, and the inputs any state starts from (an output may read every state)
                Causality::Output if d.initial() != Some(Initial::Exact) => output_dependencies(m, d)
                    .into_iter()
                    .chain(m.state_decls().iter().flat_map(|x| start_inputs(m, x)))
                    .collect(),
                Causality::CalculatedParameter => vec![],
                _ => return None,
            };
            let mut deps: Vec<usize> = inputs.into_iter().chain(params.iter().copied()).collect();
            deps.sort_unstable();
            deps.dedup();
            Some((i + 1, deps))
        })
        .collect::<Vec<_>>()
        .into_iter()
        // Model Exchange: the states (from the parameters and the inputs they start from) and their
        // derivatives (their inputs, and for each state they read the inputs that state starts from)
        .chain(state_indices(m).zip(m.state_decls()).map(|(ix, x)| {
            let mut deps: Vec<usize> = start_inputs(m, x).chain(params.iter().copied()).collect();
            deps.sort_unstable();
            deps.dedup();
            (ix, deps)
        }))
        .chain(derivative_dependencies(m).into_iter().map(|(k, on)| {
            let (n_decl, states) = (m.variables.len(), m.state_decls());
            let via_states = on
                .iter()
                .filter(|i| **i > n_decl)
                .flat_map(|i| start_inputs(m, &states[i - n_decl - 1]));
            let mut deps: Vec<usize> = on
                .iter()
                .copied()
                .filter(|i| *i <= n_decl)
                .chain(via_states)
                .chain(params.iter().copied())
                .collect();
            deps.sort_unstable();
            deps.dedup();
            (m.variables.len() + m.state_decls().len() + k + 1, deps)
        }))
        .collect()
}

/// ScalarVariable indices (1-based) of the continuous states (after the declared variables).
pub fn state_indices(m: &ModelDescription) -> impl Iterator<Item = usize> + '_ {
    let n = m.variables.len();
    (0..m.state_decls().len()).map(move |k| n + k + 1)
}

/// ScalarVariable indices of the inputs a state's start value is taken from.
fn start_inputs<'a>(m: &'a ModelDescription, x: &'a StateDescription) -> impl Iterator<Item = usize> + 'a {
    x.starts_from.iter().filter_map(move |n| input_index(m, n))
}

pub(crate) fn input_index(m: &ModelDescription, name: &str) -> Option<usize> {
    m.variables
        .iter()
        .position(|d| d.name == name && d.causality == Causality::Input)
        .map(|i| i + 1)
}

fn input_indices(m: &ModelDescription) -> impl Iterator<Item = usize> + '_ {
    m.variables
        .iter()
        .enumerate()
        .filter(|(_, d)| d.causality == Causality::Input)
        .map(|(i, _)| i + 1)
}

/// `<Derivatives>`: for each state k, the ScalarVariable indices of the inputs and states its
/// derivative depends on ([`StateDescription::depends`]: the declared list; a state that declares none
/// depends on every input and every state).
pub fn derivative_dependencies(m: &ModelDescription) -> Vec<(usize, Vec<usize>)> {
    let states = m.state_decls();
    let all: Vec<usize> = input_indices(m).chain(state_indices(m)).collect();
    let index = |n: &str| {
        input_index(m, n).or_else(|| {
            states
                .iter()
                .position(|x| x.name == n)
                .map(|k| m.variables.len() + k + 1)
        })
    };
    states
        .iter()
        .enumerate()
        .map(|(k, x)| {
            let mut deps: Vec<usize> = match &x.depends {
                None => all.clone(),
                // unknown names are refused by check_declarations before any XML is written
                Some(names) => names.iter().filter_map(|n| index(n)).collect(),
            };
            deps.sort_unstable();
            deps.dedup();
            (k, deps)
        })
        .collect()
}
