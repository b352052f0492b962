//! Expression evaluation on dynamic values (the interpreter's side of `ops`).

use super::compile::CExpr;
use crate::logic::error::EvalError;
use crate::logic::front::ast::{BinOp, Builtin, CmpOp};
use crate::logic::ops;
use crate::logic::value::{BaseTy, F64, Value};
use std::sync::atomic::Ordering;

pub fn eval(e: &CExpr, env: &[Value]) -> Result<Value, EvalError> {
    Ok(match e {
        CExpr::Slot(s) => env[*s as usize].clone(),
        CExpr::Const(v) => v.clone(),
        CExpr::Neg(_, x) => match eval(x, env)? {
            Value::Number(n) => Value::Number(n.wrapping_neg()),
            Value::Unsigned(n) => Value::Unsigned(n.wrapping_neg()),
            Value::Float(f) => Value::float(-f.0),
            other => return Err(EvalError(format!("cannot negate {other}"))),
        },
        CExpr::Bin(op, _, a, b) => bin(*op, eval(a, env)?, eval(b, env)?)?,
        CExpr::Builtin(b, ty, args) => {
            let vals: Vec<Value> = args
                .iter()
                .map(|a| eval(a, env))
                .collect::<Result<_, _>>()?;
            builtin(*b, *ty, vals)?
        }
        CExpr::Ext(f, args) => {
            let vals: Vec<Value> = args
                .iter()
                .map(|a| eval(a, env))
                .collect::<Result<_, _>>()?;
            (f.call)(&vals)
        }
        CExpr::Autoinc(counter) => Value::Number(counter.fetch_add(1, Ordering::Relaxed)),
    })
}

fn bin(op: BinOp, a: Value, b: Value) -> Result<Value, EvalError> {
    use BinOp::*;
    Ok(match (a, b) {
        (Value::Number(x), Value::Number(y)) => Value::Number(match op {
            Add => x.wrapping_add(y),
            Sub => x.wrapping_sub(y),
            Mul => x.wrapping_mul(y),
            Div => ops::div_i64(x, y)?,
            Rem => ops::rem_i64(x, y)?,
            Pow => ops::pow_i64(x, y),
        }),
        (Value::Unsigned(x), Value::Unsigned(y)) => Value::Unsigned(match op {
            Add => x.wrapping_add(y),
            Sub => x.wrapping_sub(y),
            Mul => x.wrapping_mul(y),
            Div => ops::div_u64(x, y)?,
            Rem => ops::rem_u64(x, y)?,
            Pow => ops::pow_u64(x, y),
        }),
        (Value::Float(x), Value::Float(y)) => Value::float(match op {
            Add => x.0 + y.0,
            Sub => x.0 - y.0,
            Mul => x.0 * y.0,
            Div => x.0 / y.0,
            Rem => x.0 % y.0,
            Pow => x.0.powf(y.0),
        }),
        (a, b) => {
            return Err(EvalError(format!(
                "`{}` on {} and {}",
                op.symbol(),
                a.ty(),
                b.ty()
            )));
        }
    })
}

fn sym(v: &Value) -> &str {
    v.as_symbol().unwrap_or("")
}

fn builtin(b: Builtin, ty: BaseTy, v: Vec<Value>) -> Result<Value, EvalError> {
    Ok(match b {
        Builtin::Min | Builtin::Max => {
            let mut it = v.into_iter();
            let mut acc = it
                .next()
                .ok_or_else(|| EvalError::new("min/max of nothing"))?;
            for x in it {
                let better = match (&x, &acc) {
                    (Value::Float(a), Value::Float(c)) => {
                        if b == Builtin::Min {
                            a.0 < c.0
                        } else {
                            a.0 > c.0
                        }
                    }
                    _ => {
                        if b == Builtin::Min {
                            x < acc
                        } else {
                            x > acc
                        }
                    }
                };
                if better {
                    acc = x;
                }
            }
            acc
        }
        Builtin::Cat => {
            let parts: Vec<&str> = v.iter().map(sym).collect();
            Value::Symbol(ops::cat_bounded(&parts)?)
        }
        Builtin::Strlen => Value::Number(ops::strlen(sym(&v[0]))),
        Builtin::Substr => Value::Symbol(ops::substr(
            sym(&v[0]),
            v[1].as_number().unwrap_or(0),
            v[2].as_number().unwrap_or(0),
        )?),
        Builtin::Ord => Value::Number(ops::ord(sym(&v[0]))),
        Builtin::ToNumber => Value::Number(ops::to_number(sym(&v[0]))?),
        Builtin::ToUnsigned => Value::Unsigned(ops::to_unsigned(sym(&v[0]))?),
        Builtin::ToFloat => Value::Float(ops::to_float(sym(&v[0]))?),
        Builtin::ToString => Value::Symbol(match (&v[0], ty) {
            (Value::Number(n), _) => ops::i64_to_string(*n),
            (Value::Unsigned(n), _) => ops::u64_to_string(*n),
            (Value::Float(f), _) => ops::f64_to_string(*f),
            (other, _) => return Err(EvalError(format!("to_string of {}", other.ty()))),
        }),
        Builtin::Itof => Value::Float(F64(v[0].as_number().unwrap_or(0) as f64)),
        Builtin::Itou => Value::Unsigned(v[0].as_number().unwrap_or(0) as u64),
        Builtin::Utoi => match v[0] {
            Value::Unsigned(u) => Value::Number(u as i64),
            _ => return Err(EvalError::new("utoi of a non-unsigned value")),
        },
        Builtin::Utof => match v[0] {
            Value::Unsigned(u) => Value::float(u as f64),
            _ => return Err(EvalError::new("utof of a non-unsigned value")),
        },
        Builtin::Ftoi => Value::Number(v[0].as_float().unwrap_or(0.0) as i64),
        Builtin::Ftou => Value::Unsigned(v[0].as_float().unwrap_or(0.0) as u64),
        Builtin::Autoinc => return Err(EvalError("autoinc() outside a rule".into())),
    })
}

pub fn compare(op: CmpOp, a: &Value, b: &Value) -> bool {
    if let (Value::Float(x), Value::Float(y)) = (a, b) {
        return ops::float_cmp(op, x.0, y.0);
    }
    match op {
        CmpOp::Eq => a == b,
        CmpOp::Ne => a != b,
        CmpOp::Lt => a < b,
        CmpOp::Le => a <= b,
        CmpOp::Gt => a > b,
        CmpOp::Ge => a >= b,
    }
}
