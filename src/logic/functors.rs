//! The registry of Rust functors (`@name(args)`), shared by the interpreter
//! (through `FUNCTORS`) and the compiled engine (which calls `defs::name`
//! directly). The entries are in `functor_defs.rs`.

use super::front::FunctorSig;
use super::value::{Column, F64, Iso, OBox, Sym, Value, Vec3};

/// A registered functor: its signature and a call on dynamic values.
pub struct Functor {
    pub sig: FunctorSig,
    /// Arguments have been type-checked against `sig`.
    pub call: fn(&[Value]) -> Value,
}

macro_rules! functor_table {
    ($( $(#[$doc:meta])* fn $name:ident ( $($arg:ident : $ty:ident),* ) -> $ret:ident $body:block )*) => {
        /// Typed implementations; generated compiled programs call these.
        #[allow(clippy::all)]
        pub mod defs {
            use super::*;
            $( $(#[$doc])* pub fn $name($($arg: $ty),*) -> $ret $body )*
        }
        /// Every functor, sorted by name.
        pub static FUNCTORS: &[Functor] = &[
            $( Functor {
                sig: FunctorSig {
                    name: stringify!($name),
                    params: &[$(<$ty as Column>::TY),*],
                    ret: <$ret as Column>::TY,
                },
                call: |args: &[Value]| {
                    let mut _i = 0usize;
                    $( let $arg = <$ty as Column>::from_value(&args[_i]); _i += 1; )*
                    defs::$name($($arg),*).into_value()
                },
            }, )*
        ];
    };
}

include!("functor_defs.rs");

/// Signatures for the checker.
pub fn signatures() -> Vec<FunctorSig> {
    FUNCTORS.iter().map(|f| f.sig).collect()
}

pub fn lookup(name: &str) -> Option<&'static Functor> {
    FUNCTORS.iter().find(|f| f.sig.name == name)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn compose_apply_inverse_agree() {
        let a = defs::iso(
            Vec3::new(1.0, 2.0, 3.0),
            Vec3::new(0.0, 0.0, std::f64::consts::FRAC_PI_2),
        );
        let p = Vec3::new(1.0, 0.0, 0.0);
        let q = defs::apply(a, p);
        assert!((q.0 - nalgebra::Vector3::new(1.0, 3.0, 3.0)).norm() < 1e-12);
        let back = defs::apply(defs::inverse(a), q);
        assert!((back.0 - p.0).norm() < 1e-12);
        let b = defs::box_contains(
            defs::obox(a, Vec3::new(0.5, 0.5, 0.5)),
            Vec3::new(1.2, 2.2, 3.0),
        );
        assert_eq!(b, 1);
    }

    #[test]
    fn registry_calls_match_typed_functions() {
        let f = lookup("dist").unwrap();
        let v = (f.call)(&[
            Value::Vec3(Vec3::new(0.0, 0.0, 0.0)),
            Value::Vec3(Vec3::new(3.0, 4.0, 0.0)),
        ]);
        assert_eq!(v, Value::float(5.0));
        assert_eq!(f.sig.params.len(), 2);
    }
}
