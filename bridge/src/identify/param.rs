//! What a fit reports for one parameter: a value with its uncertainty, or why there is none.

/// A fitted value with its uncertainty (one standard deviation), or why there is none.
pub type Param<T> = Result<(T, T), String>;
