//! GLSL.std.450, the extended instructions glslang emits for GLSL's built-in functions, as C. Each is written
//! as GLSL 4.50 (sec. 8) and the GLSL.std.450 specification define it; the transcendental ones call the
//! prelude's `m_` functions, which each dialect maps to its own library (and its own precision: the compiler
//! options of the target decide, as a Vulkan driver's do). Half-precision arguments are computed in f32
//! between exact conversions, as NVIDIA and Intel evaluate fp16 transcendentals.

use super::TranslateError;
use super::body::FunctionWriter;
use super::ctypes::Scalar;
use super::ops::{as_f32, comp, fbin};
use rspirv::dr::Instruction;
use rspirv::spirv::{GlslStd450Op as G, Word};
use std::fmt::Write;

/// The prelude function of a one-argument float function.
fn unary_name(op: G) -> Option<&'static str> {
    Some(match op {
        G::Round => "m_round",
        G::RoundEven => "m_rint",
        G::Trunc => "m_trunc",
        G::FAbs => "m_fabs",
        G::Floor => "m_floor",
        G::Ceil => "m_ceil",
        G::Sin => "m_sin",
        G::Cos => "m_cos",
        G::Tan => "m_tan",
        G::Asin => "m_asin",
        G::Acos => "m_acos",
        G::Atan => "m_atan",
        G::Sinh => "m_sinh",
        G::Cosh => "m_cosh",
        G::Tanh => "m_tanh",
        G::Asinh => "m_asinh",
        G::Acosh => "m_acosh",
        G::Atanh => "m_atanh",
        G::Exp => "m_exp",
        G::Log => "m_log",
        G::Exp2 => "m_exp2",
        G::Log2 => "m_log2",
        G::Sqrt => "m_sqrt",
        G::InverseSqrt => "m_rsqrt",
        _ => return None,
    })
}

/// A float function of f32 arguments in scalar kind `s`: f32 as is, f64 through `_d`, f16 through `_h` (the
/// prelude's half form: the f32 function between exact conversions, common.h; the f64 reference applies
/// half precision's rules to it).
fn float_call(s: Scalar, name: &str, args: &[String]) -> String {
    match s {
        Scalar::F64 => format!("{name}_d({})", args.join(", ")),
        Scalar::F16 => format!("{name}_h({})", args.join(", ")),
        _ => format!("{name}({})", args.join(", ")),
    }
}

/// `a < b` in scalar kind `s` (halves with the prelude's native comparison).
fn less(s: Scalar, a: &str, b: &str) -> String {
    if s == Scalar::F16 { format!("h_lt({a}, {b})") } else { format!("({a} < {b})") }
}

/// `min` or `max` (`what`) of `a` and `b` in scalar kind `s`: GLSL.std.450's FMin/FMax, the other operand where
/// one is NaN; halves with the prelude's native `h_min`/`h_max`.
fn min_max(s: Scalar, what: &str, a: &str, b: &str) -> String {
    if s == Scalar::F16 {
        format!("h_{what}({a}, {b})")
    } else {
        float_call(s, &format!("m_f{what}"), &[a.to_string(), b.to_string()])
    }
}

/// A float literal in scalar kind `s`.
fn lit(s: Scalar, x: f32) -> String {
    match s {
        Scalar::F16 => format!("h_from_f32({x:?}f)"),
        Scalar::F64 => format!("{x:?}"),
        _ => format!("{x:?}f"),
    }
}

impl FunctionWriter<'_> {
    /// A fresh temporary of C type `ty` holding `expr` (so that an operand used twice is computed once).
    fn temp(&mut self, ty: &str, expr: String) -> String {
        let name = format!("t{}_{}", self.decls.len(), self.body.len());
        self.decls.push(format!("{ty} {name};"));
        writeln!(self.body, "  {name} = {expr};").unwrap();
        name
    }

    pub fn ext_inst(&mut self, inst: &Instruction) -> Result<String, TranslateError> {
        if !self.m.glsl_std_450.contains(&Self::id(inst, 0)) {
            return Err(self.err("an extended instruction outside GLSL.std.450"));
        }
        let op = G::from_u32(Self::lit(inst, 1))
            .ok_or_else(|| self.err(format!("the GLSL.std.450 instruction {}", Self::lit(inst, 1))))?;
        if matches!(
            op,
            G::Determinant
                | G::MatrixInverse
                | G::Modf
                | G::ModfStruct
                | G::Frexp
                | G::FrexpStruct
                | G::InterpolateAtCentroid
                | G::InterpolateAtSample
                | G::InterpolateAtOffset
                | G::PackDouble2x32
                | G::UnpackDouble2x32
        ) {
            let name = format!("{op:?}");
            return Err(self.err(format!("the GLSL.std.450 function {name} (GLSL's {})", name.to_ascii_lowercase())));
        }
        let ty = inst.result_type.unwrap_or(0);
        let args: Vec<Word> = (2..inst.operands.len()).map(|k| Self::id(inst, k)).collect();
        let arg_ty = args.first().and_then(|a| self.m.type_of(*a)).unwrap_or(ty);
        let s = self.m.scalar(self.m.scalar_of(arg_ty)).map_err(|e| self.err(e.construct))?;
        let exprs = args.iter().map(|a| self.v(*a)).collect::<Result<Vec<_>, _>>()?;
        let ns: Vec<u32> = args.iter().map(|a| self.m.components(self.m.type_of(*a).unwrap_or(0))).collect();
        let n = self.m.components(ty);
        if let Some(e) = self.geometric(op, s, &exprs, ns.first().copied().unwrap_or(1), ty, arg_ty)? {
            return Ok(e);
        }
        if let Some(e) = self.packing(op, &exprs, ns.first().copied().unwrap_or(1), ty)? {
            return Ok(e);
        }
        let mut parts = Vec::new();
        for k in 0..n {
            let a: Vec<String> = exprs.iter().zip(&ns).map(|(e, m)| comp(e, *m, k)).collect();
            parts.push(self.componentwise(op, s, &a)?);
        }
        self.build(ty, parts)
    }

    /// One component of a componentwise GLSL.std.450 function.
    fn componentwise(&self, op: G, s: Scalar, a: &[String]) -> Result<String, TranslateError> {
        if let Some(name) = unary_name(op) {
            return Ok(float_call(s, name, &a[..1]));
        }
        let int = |x: &str| format!("(i32)({x})");
        let uint = |x: &str| format!("(u32)({x})");
        Ok(match op {
            G::FSign => format!(
                "({} ? {} : ({} ? {} : {}))",
                less(s, &lit(s, 0.0), &a[0]),
                lit(s, 1.0),
                less(s, &a[0], &lit(s, 0.0)),
                lit(s, -1.0),
                lit(s, 0.0)
            ),
            G::Fract => fbin(s, "-", &a[0], &float_call(s, "m_floor", &a[..1])),
            G::Radians => fbin(s, "*", &a[0], &lit(s, std::f32::consts::PI / 180.0)),
            G::Degrees => fbin(s, "*", &a[0], &lit(s, 180.0 / std::f32::consts::PI)),
            G::Pow => float_call(s, "m_pow", &a[..2]),
            G::Atan2 => float_call(s, "m_atan2", &a[..2]),
            G::FMin | G::NMin => min_max(s, "min", &a[0], &a[1]),
            G::FMax | G::NMax => min_max(s, "max", &a[0], &a[1]),
            G::FClamp | G::NClamp => min_max(s, "min", &min_max(s, "max", &a[0], &a[1]), &a[2]),
            G::Step => format!("({} ? {} : {})", less(s, &a[1], &a[0]), lit(s, 0.0), lit(s, 1.0)),
            G::SmoothStep => float_call(s, "m_smoothstep", &a[..3]),
            // GLSL 4.50 8.3: mix(x, y, a) = x (1 - a) + y a.
            G::FMix => {
                fbin(s, "+", &fbin(s, "*", &a[0], &fbin(s, "-", &lit(s, 1.0), &a[2])), &fbin(s, "*", &a[1], &a[2]))
            }
            G::Fma if s == Scalar::F16 => format!("h_fma({}, {}, {})", a[0], a[1], a[2]),
            G::Fma => float_call(s, "m_fma", &a[..3]),
            G::Ldexp => float_call(s, "m_ldexp", &[a[0].clone(), int(&a[1])]),
            G::SAbs => format!("m_sabs({})", int(&a[0])),
            G::SSign => format!("({0} > 0 ? 1 : ({0} < 0 ? -1 : 0))", int(&a[0])),
            G::UMin => format!("m_umin({}, {})", uint(&a[0]), uint(&a[1])),
            G::UMax => format!("m_umax({}, {})", uint(&a[0]), uint(&a[1])),
            G::SMin => format!("m_smin({}, {})", int(&a[0]), int(&a[1])),
            G::SMax => format!("m_smax({}, {})", int(&a[0]), int(&a[1])),
            G::UClamp => format!("m_umin(m_umax({}, {}), {})", uint(&a[0]), uint(&a[1]), uint(&a[2])),
            G::SClamp => format!("m_smin(m_smax({}, {}), {})", int(&a[0]), int(&a[1]), int(&a[2])),
            G::FindILsb => format!("m_findlsb({})", uint(&a[0])),
            G::FindSMsb => format!("m_findsmsb({})", int(&a[0])),
            G::FindUMsb => format!("m_findumsb({})", uint(&a[0])),
            other => return Err(self.err(format!("the GLSL.std.450 function {other:?}"))),
        })
    }

    /// The geometric functions of GLSL 4.50 8.5 (not componentwise).
    fn geometric(
        &mut self,
        op: G,
        s: Scalar,
        a: &[String],
        n: u32,
        ty: Word,
        arg_ty: Word,
    ) -> Result<Option<String>, TranslateError> {
        let scalar_ty = s.c_name();
        let e = match op {
            G::Length if n == 1 => float_call(s, "m_fabs", &a[..1]),
            G::Length => float_call(s, "m_sqrt", &[self.dot(s, &a[0], &a[0], n)]),
            G::Distance => {
                let diff = (0..n).map(|k| fbin(s, "-", &comp(&a[0], n, k), &comp(&a[1], n, k))).collect::<Vec<_>>();
                let d = if n == 1 {
                    diff[0].clone()
                } else {
                    self.temp(&self.m.c_type(arg_ty)?, self.build(arg_ty, diff)?)
                };
                if n == 1 { float_call(s, "m_fabs", &[d]) } else { float_call(s, "m_sqrt", &[self.dot(s, &d, &d, n)]) }
            }
            G::Normalize if n == 1 => format!("({} < {} ? {} : {})", a[0], lit(s, 0.0), lit(s, -1.0), lit(s, 1.0)),
            G::Normalize => {
                let r = self.temp(scalar_ty, float_call(s, "m_rsqrt", &[self.dot(s, &a[0], &a[0], n)]));
                self.build(ty, (0..n).map(|k| fbin(s, "*", &comp(&a[0], n, k), &r)).collect())?
            }
            G::Cross => {
                let c = |i: u32, j: u32| {
                    fbin(
                        s,
                        "-",
                        &fbin(s, "*", &comp(&a[0], 3, i), &comp(&a[1], 3, j)),
                        &fbin(s, "*", &comp(&a[1], 3, i), &comp(&a[0], 3, j)),
                    )
                };
                self.build(ty, vec![c(1, 2), c(2, 0), c(0, 1)])?
            }
            G::FaceForward => self.face_forward(s, a, n, ty)?,
            G::Reflect => {
                // I - 2 dot(N, I) N
                let d = self.temp(scalar_ty, self.dot(s, &a[1], &a[0], n));
                let twice = fbin(s, "*", &lit(s, 2.0), &d);
                self.build(
                    ty,
                    (0..n)
                        .map(|k| fbin(s, "-", &comp(&a[0], n, k), &fbin(s, "*", &twice, &comp(&a[1], n, k))))
                        .collect(),
                )?
            }
            G::Refract => self.refract(s, a, n, ty)?,
            _ => return Ok(None),
        };
        Ok(Some(e))
    }

    /// faceForward(N, I, Nref): N where dot(Nref, I) < 0, else -N.
    fn face_forward(&mut self, s: Scalar, a: &[String], n: u32, ty: Word) -> Result<String, TranslateError> {
        let d = self.dot(s, &a[2], &a[1], n);
        let neg = self.build(
            ty,
            (0..n)
                .map(|k| {
                    if s == Scalar::F16 {
                        format!("h_neg({})", comp(&a[0], n, k))
                    } else {
                        format!("(-{})", comp(&a[0], n, k))
                    }
                })
                .collect(),
        )?;
        Ok(format!("({} < {} ? {} : {neg})", as_f32(s, &d), "0.0f", a[0]))
    }

    /// refract(I, N, eta), from its definition in GLSL 4.50 8.5.
    fn refract(&mut self, s: Scalar, a: &[String], n: u32, ty: Word) -> Result<String, TranslateError> {
        // k = 1 - eta^2 (1 - dot(N, I)^2); k < 0: 0, else eta I - (eta dot(N, I) + sqrt(k)) N
        let scalar_ty = s.c_name();
        let d = self.temp(scalar_ty, self.dot(s, &a[1], &a[0], n));
        let eta = &a[2];
        let k = self.temp(
            scalar_ty,
            fbin(
                s,
                "-",
                &lit(s, 1.0),
                &fbin(s, "*", &fbin(s, "*", eta, eta), &fbin(s, "-", &lit(s, 1.0), &fbin(s, "*", &d, &d))),
            ),
        );
        let f = self.temp(scalar_ty, fbin(s, "+", &fbin(s, "*", eta, &d), &float_call(s, "m_sqrt", &[k.clone()])));
        let r = self.build(
            ty,
            (0..n)
                .map(|c| fbin(s, "-", &fbin(s, "*", eta, &comp(&a[0], n, c)), &fbin(s, "*", &f, &comp(&a[1], n, c))))
                .collect(),
        )?;
        Ok(format!("({} < 0.0f ? {} : {r})", as_f32(s, &k), self.m.zero(ty)?))
    }

    /// The packing functions of GLSL 4.50 8.4, from their definitions.
    fn packing(&mut self, op: G, a: &[String], n: u32, ty: Word) -> Result<Option<String>, TranslateError> {
        let p = a.first().cloned().unwrap_or_default();
        if let Some(e) = pack(op, &p, n) {
            return Ok(Some(e));
        }
        let e = match op {
            G::UnpackUnorm4x8 => self
                .build(ty, (0..4).map(|k| format!("m_fdiv((float)(({p} >> {}u) & 255u), 255.0f)", 8 * k)).collect())?,
            G::UnpackSnorm4x8 => self.build(
                ty,
                (0..4)
                    .map(|k| {
                        clamp(format!("m_fdiv((float)((i32)({p} << {}u) >> 24), 127.0f)", 24 - 8 * k), "-1.0f", "1.0f")
                    })
                    .collect(),
            )?,
            G::UnpackUnorm2x16 => self.build(
                ty,
                (0..2).map(|k| format!("m_fdiv((float)(({p} >> {}u) & 65535u), 65535.0f)", 16 * k)).collect(),
            )?,
            G::UnpackSnorm2x16 => self.build(
                ty,
                (0..2)
                    .map(|k| {
                        clamp(
                            format!("m_fdiv((float)((i32)({p} << {}u) >> 16), 32767.0f)", 16 - 16 * k),
                            "-1.0f",
                            "1.0f",
                        )
                    })
                    .collect(),
            )?,
            G::UnpackHalf2x16 => self
                .build(ty, (0..2).map(|k| format!("h_to_f32(h_from_bits(({p} >> {}u) & 65535u))", 16 * k)).collect())?,
            _ => return Ok(None),
        };
        Ok(Some(e))
    }
}

/// `x` clamped to `lo`..=`hi`.
fn clamp(x: String, lo: &str, hi: &str) -> String {
    format!("m_fmin(m_fmax({x}, {lo}), {hi})")
}

/// The pack functions of GLSL 4.50 8.4 (`op` one of them, or None), of the `n`-component vector `p`.
fn pack(op: G, p: &str, n: u32) -> Option<String> {
    let e = match op {
        G::PackUnorm4x8 => (0..4)
            .map(|k| format!("((u32)m_rint({} * 255.0f) << {}u)", clamp(comp(p, n, k), "0.0f", "1.0f"), 8 * k))
            .collect::<Vec<_>>()
            .join(" | "),
        G::PackSnorm4x8 => (0..4)
            .map(|k| {
                format!("(((u32)(i32)m_rint({} * 127.0f) & 255u) << {}u)", clamp(comp(p, n, k), "-1.0f", "1.0f"), 8 * k)
            })
            .collect::<Vec<_>>()
            .join(" | "),
        G::PackUnorm2x16 => (0..2)
            .map(|k| format!("((u32)m_rint({} * 65535.0f) << {}u)", clamp(comp(p, n, k), "0.0f", "1.0f"), 16 * k))
            .collect::<Vec<_>>()
            .join(" | "),
        G::PackSnorm2x16 => (0..2)
            .map(|k| {
                format!(
                    "(((u32)(i32)m_rint({} * 32767.0f) & 65535u) << {}u)",
                    clamp(comp(p, n, k), "-1.0f", "1.0f"),
                    16 * k
                )
            })
            .collect::<Vec<_>>()
            .join(" | "),
        G::PackHalf2x16 => (0..2)
            .map(|k| format!("((u32)h_bits(h_from_f32({})) << {}u)", comp(p, n, k), 16 * k))
            .collect::<Vec<_>>()
            .join(" | "),
        _ => return None,
    };
    Some(format!("({e})"))
}
