//! `fog-sim`: the training PC's library behind the `fogsim` binary.
