//! The instruction set the Gauss-point kernels and the pattern's fused products run
//! with, chosen once per process from what the CPU reports.
//!
//! The binary is built for the baseline x86-64 (SSE2), so that it runs on any such
//! machine; the element loop of the Gauss-point pass and the fused products
//! `K u`, `M w` of a step (`Pattern::matvec2`) are compiled a second time with AVX2
//! and the faster copy is taken where the CPU has it. The AVX2 copy performs
//! the same operations in the same order (no fused multiply-add is written in the
//! pass, and the compiler never contracts a product and a sum into one), so its
//! results are the baseline's bit for bit;
//! `tests/unit/gauss_point_pass.rs::the_avx2_element_loop_gives_the_baselines_bits`
//! compares the two on the machine that runs the tests, and
//! `assembly::tests::the_node_pair_mass_gives_the_full_products_bit_for_bit` the
//! fused products against the separate ones (`theory/gauss_point_pass.md`).
//!
//! `ROTHE_SIMD=baseline` in the environment keeps the baseline copy (to compare, or
//! to time, the two on one machine).

use std::sync::OnceLock;

/// An instruction set of the Gauss-point kernels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Simd {
    /// The baseline of the target (SSE2 on x86-64).
    Baseline,
    /// AVX2 (x86-64 only).
    Avx2,
}

impl Simd {
    /// The fastest set this CPU runs, unless `ROTHE_SIMD=baseline` asks for the
    /// baseline; read once per process.
    pub fn detected() -> Simd {
        static CHOSEN: OnceLock<Simd> = OnceLock::new();
        *CHOSEN.get_or_init(|| match Simd::asked() {
            Ok(Some(Simd::Baseline)) => Simd::Baseline,
            _ => Simd::available(),
        })
    }

    /// What `ROTHE_SIMD` asks for: `baseline`, `avx2` (the default where the CPU has
    /// it), unset or empty (`None`); any other value is an error naming the
    /// variable, which the command line and the Python module report at start.
    pub fn asked() -> Result<Option<Simd>, String> {
        match std::env::var("ROTHE_SIMD") {
            Err(std::env::VarError::NotPresent) => Ok(None),
            Ok(v) if v.trim().is_empty() => Ok(None),
            Ok(v) if v.trim() == "baseline" => Ok(Some(Simd::Baseline)),
            Ok(v) if v.trim() == "avx2" => Ok(Some(Simd::Avx2)),
            Ok(v) => Err(format!(
                "ROTHE_SIMD = `{v}`: expected `baseline` or `avx2` (or unset, for the \
                 fastest set the CPU has)"
            )),
            Err(e) => Err(format!("ROTHE_SIMD: {e}")),
        }
    }

    /// The fastest set the CPU has, whatever the environment asks.
    pub fn available() -> Simd {
        #[cfg(target_arch = "x86_64")]
        {
            if std::is_x86_feature_detected!("avx2") {
                return Simd::Avx2;
            }
        }
        Simd::Baseline
    }

    /// The name `summary.json` and `rothe check` give it.
    pub fn name(self) -> &'static str {
        match self {
            Simd::Baseline => "baseline",
            Simd::Avx2 => "avx2",
        }
    }
}
