//! Cross-crate and end-to-end tests live in `tests/`.

/// The Rust blocks of `docs/guide/controllers.md` (the out-of-tree controller, the check of a
/// law against a run), compiled as doctests: the guide's code is code that builds.
#[cfg(doctest)]
#[doc = include_str!("../docs/guide/controllers.md")]
pub struct ControllersGuide;
