//! `scene_table!`: one table of the scene file declared once, each key with its doc, type and
//! default ([`super::raw`]'s tables and each rotor model's own keys, [`super::models`]).

/// Declares one table of the scene file, each key once: its doc, its field and type, and its
/// default (the study's value). Gives the struct (every key optional in the file, unknown keys
/// refused), its `Default`, the default in each field's doc, and `KEYS`, the keys in
/// declaration order (the guide's key table, `docs/guide/scenes.md`, is checked against them
/// and the defaults by `tests/tests/docs.rs`).
macro_rules! scene_table {
    (
        $(#[$sattr:meta])*
        pub struct $name:ident {
            $(
                $(#[$attr:meta])*
                pub $field:ident : $ty:ty = $default:expr
            ),* $(,)?
        }
    ) => {
        $(#[$sattr])*
        #[derive(Clone, Debug, Serialize, Deserialize)]
        #[serde(default, deny_unknown_fields)]
        pub struct $name {
            $(
                $(#[$attr])*
                #[doc = ""]
                #[doc = concat!("Default: `", stringify!($default), "`.")]
                pub $field: $ty,
            )*
        }

        impl Default for $name {
            fn default() -> Self {
                Self { $($field: $default),* }
            }
        }

        impl $name {
            /// The keys of this table as the scene file spells them, in declaration order.
            pub const KEYS: &'static [&'static str] = &[$(stringify!($field)),*];
        }
    };
}
pub(crate) use scene_table;
