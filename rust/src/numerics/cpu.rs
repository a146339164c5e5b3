//! The processor a run is on, the instruction sets the engine uses there (so that benchmark
//! figures from different machines are never compared blind), and the choice of the compiled
//! kernels: the scalar integration loop's ([`ScalarKernel`]) and the lockstep lanes' ([`Kernel`]).
//!
//! The build targets baseline x86-64 (SSE2) so that one wheel runs everywhere; the scalar
//! integration loop is compiled again for AVX and FMA ([`ScalarKernel`]) and
//! the ensemble's lockstep kernel for AVX2 and for AVX-512F, both with FMA
//! ([`Kernel`]), the newest the processor has picked at run time.
//! The FMA kernels round the paper model's multiply-adds once, so their bits differ from the
//! portable ones (within the integration's accuracy); scalar and lane kernels are picked to match.

use std::sync::OnceLock;

/// Instruction sets worth reporting, oldest first.
#[cfg(target_arch = "x86_64")]
const LEVELS: [&str; 6] = ["sse4.2", "avx", "avx2", "fma", "avx512f", "avx512vl"];

/// The processor's name as the OS reports it ("unknown" when it does not).
pub fn model_name() -> String {
    if let Ok(info) = std::fs::read_to_string("/proc/cpuinfo") {
        for line in info.lines() {
            if let Some((key, value)) = line.split_once(':') {
                if key.trim() == "model name" {
                    return value.trim().to_string();
                }
            }
        }
    }
    format!("unknown {} processor", std::env::consts::ARCH)
}

/// Which of [`LEVELS`] this processor has.
pub fn detected() -> Vec<&'static str> {
    #[cfg(target_arch = "x86_64")]
    {
        let has = |name: &str| match name {
            "sse4.2" => std::arch::is_x86_feature_detected!("sse4.2"),
            "avx" => std::arch::is_x86_feature_detected!("avx"),
            "avx2" => std::arch::is_x86_feature_detected!("avx2"),
            "fma" => std::arch::is_x86_feature_detected!("fma"),
            "avx512f" => std::arch::is_x86_feature_detected!("avx512f"),
            "avx512vl" => std::arch::is_x86_feature_detected!("avx512vl"),
            _ => false,
        };
        LEVELS.iter().copied().filter(|n| has(n)).collect()
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        Vec::new()
    }
}

/// Which of [`LEVELS`] the whole build may use everywhere (its compile-time target features).
pub fn compiled() -> Vec<&'static str> {
    let mut out = Vec::new();
    if cfg!(target_feature = "sse4.2") {
        out.push("sse4.2");
    }
    if cfg!(target_feature = "avx") {
        out.push("avx");
    }
    if cfg!(target_feature = "avx2") {
        out.push("avx2");
    }
    if cfg!(target_feature = "fma") {
        out.push("fma");
    }
    if cfg!(target_feature = "avx512f") {
        out.push("avx512f");
    }
    if cfg!(target_feature = "avx512vl") {
        out.push("avx512vl");
    }
    out
}

/// One line for a benchmark's header: processor, what it has, what the build uses.
pub fn describe() -> String {
    let list = |v: Vec<&str>| {
        if v.is_empty() {
            "baseline".to_string()
        } else {
            v.join(" ")
        }
    };
    format!(
        "CPU: {} | has: {} | build: {} {} | scalar kernel: {}, ensemble kernel: {} (chosen at \
         run time)",
        model_name(),
        list(detected()),
        std::env::consts::ARCH,
        list(compiled()),
        ScalarKernel::detect().name(),
        Kernel::detect().name(),
    )
}

/// Which compilation of the scalar integration loop ([`crate::numerics::integrate::solve`]'s loop over segments and steps,
/// with the right-hand side inlined into it) runs.
///
/// The fused one differs from the portable one in the last bits: the paper model's right-hand
/// side ([`crate::numerics::integrate::OdeSystem::rhs_fused`]) rounds each of its multiply-adds once. Every other
/// operation, and every other model, is the same in both. The lockstep lanes pick theirs to
/// match ([`Kernel::scalar`]), so a run gives the same bits alone or in a lane.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ScalarKernel {
    /// The build's baseline instruction set (SSE2 on x86-64), multiply and add rounded apart:
    /// the same bits on every processor.
    Portable,
    /// Compiled for AVX and FMA (x86-64 only, when the processor has both): the sin/cos
    /// polynomials, the hinge's and the layers' balances as fused multiply-adds, which shortens
    /// the right-hand side's chain of dependent operations.
    Fma,
}

impl ScalarKernel {
    /// Whether this processor has the kernel's instruction sets.
    pub fn runs_here(self) -> bool {
        match self {
            ScalarKernel::Portable => true,
            #[cfg(target_arch = "x86_64")]
            ScalarKernel::Fma => {
                std::arch::is_x86_feature_detected!("avx")
                    && std::arch::is_x86_feature_detected!("fma")
            }
            #[cfg(not(target_arch = "x86_64"))]
            ScalarKernel::Fma => false,
        }
    }

    /// The kernel runs use here: the one matching the lockstep kernel chosen
    /// ([`Kernel::detect`], which [`KERNEL_VARIABLE`] can set to portable).
    pub fn detect() -> Self {
        Kernel::detect().scalar()
    }

    /// Every kernel this processor runs, the portable one first.
    pub fn available() -> Vec<Self> {
        [ScalarKernel::Portable, ScalarKernel::Fma]
            .into_iter()
            .filter(|k| k.runs_here())
            .collect()
    }

    /// Whether the kernel's multiply-adds round once.
    pub fn fused(self) -> bool {
        self == ScalarKernel::Fma
    }

    pub fn name(self) -> &'static str {
        match self {
            ScalarKernel::Portable => "portable",
            ScalarKernel::Fma => "fma",
        }
    }
}

/// The environment variable that picks the kernels: `portable` runs the portable scalar and
/// lane kernels on any processor (the engine's own arithmetic without FMA; the C library may
/// still use its FMA paths); unset, or `auto`, the best the processor has. Read once, at the
/// first run.
pub const KERNEL_VARIABLE: &str = "THERMOJITTER_KERNEL";

/// What [`KERNEL_VARIABLE`] may be set to.
pub const KERNEL_CHOICES: [&str; 2] = ["auto", "portable"];

/// Which compilation of the lockstep lane kernel runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kernel {
    /// The build's baseline instruction set (SSE2 on x86-64).
    Portable,
    /// AVX2 and FMA (x86-64 only, when the processor has both).
    Avx2,
    /// AVX-512F and FMA (x86-64 only, when the processor has both).
    Avx512,
}

#[cfg(test)]
thread_local! {
    /// Set by [`on_portable`]: this thread's runs take the portable kernels.
    static PORTABLE_HERE: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

/// Runs `f` with the portable kernels chosen on this thread (tests that pin portable bits).
#[cfg(test)]
pub(crate) fn on_portable<R>(f: impl FnOnce() -> R) -> R {
    PORTABLE_HERE.with(|p| p.set(true));
    let out = f();
    PORTABLE_HERE.with(|p| p.set(false));
    out
}

impl Kernel {
    /// Every kernel, oldest instruction set first.
    const ALL: [Kernel; 3] = [Kernel::Portable, Kernel::Avx2, Kernel::Avx512];

    /// Whether this processor has the kernel's instruction sets.
    pub fn runs_here(self) -> bool {
        match self {
            Kernel::Portable => true,
            #[cfg(target_arch = "x86_64")]
            Kernel::Avx2 => {
                std::arch::is_x86_feature_detected!("avx2")
                    && std::arch::is_x86_feature_detected!("fma")
            }
            #[cfg(target_arch = "x86_64")]
            Kernel::Avx512 => {
                std::arch::is_x86_feature_detected!("avx512f")
                    && std::arch::is_x86_feature_detected!("fma")
            }
            #[cfg(not(target_arch = "x86_64"))]
            _ => false,
        }
    }

    /// The kernel runs use here: the best this processor runs, or the portable one when
    /// [`KERNEL_VARIABLE`] says `portable`.
    pub fn detect() -> Self {
        #[cfg(test)]
        if PORTABLE_HERE.with(|p| p.get()) {
            return Kernel::Portable;
        }
        static CHOSEN: OnceLock<Kernel> = OnceLock::new();
        *CHOSEN.get_or_init(|| {
            if portable_requested() {
                return Kernel::Portable;
            }
            Kernel::ALL
                .into_iter()
                .rev()
                .find(|k| k.runs_here())
                .unwrap_or(Kernel::Portable)
        })
    }

    /// The scalar kernel whose bits this one's lanes give.
    pub fn scalar(self) -> ScalarKernel {
        match self {
            Kernel::Portable => ScalarKernel::Portable,
            Kernel::Avx2 | Kernel::Avx512 => ScalarKernel::Fma,
        }
    }

    /// Every kernel this processor runs, the portable one first.
    pub fn available() -> Vec<Self> {
        Kernel::ALL.into_iter().filter(|k| k.runs_here()).collect()
    }

    pub fn name(self) -> &'static str {
        match self {
            Kernel::Portable => "portable",
            Kernel::Avx2 => "avx2",
            Kernel::Avx512 => "avx512f",
        }
    }
}

/// Whether [`KERNEL_VARIABLE`] asks for the portable kernels.
pub fn portable_requested() -> bool {
    std::env::var(KERNEL_VARIABLE).is_ok_and(|v| v.trim().eq_ignore_ascii_case("portable"))
}
