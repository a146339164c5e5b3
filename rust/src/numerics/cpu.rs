//! The processor a run is on and the instruction sets the engine uses there, so that benchmark
//! figures from different machines are never compared blind.
//!
//! The build targets baseline x86-64 (SSE2) so that one wheel runs everywhere; the scalar
//! integration loop is compiled again for AVX and FMA ([`crate::numerics::integrate::ScalarKernel`]) and
//! the ensemble's lockstep kernel for AVX2 and for AVX-512F, both with FMA
//! ([`crate::runs::lockstep::Kernel`]), the newest the processor has picked at run time.
//! The FMA kernels round the paper model's multiply-adds once, so their bits differ from the
//! portable ones (within the integration's accuracy); scalar and lane kernels are picked to match.

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
        crate::numerics::integrate::ScalarKernel::detect().name(),
        crate::runs::lockstep::Kernel::detect().name(),
    )
}
