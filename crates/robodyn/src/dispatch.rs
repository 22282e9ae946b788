//! Run-time choice of instruction set, written once: [`multiversion!`] defines a function whose
//! body is compiled again for wider instruction sets (AVX2 and FMA, AVX-512) and runs the widest
//! build the processor has, checked at each call (the check is a load of a cached flag). One
//! binary then serves every x86-64 processor; elsewhere only the baseline build exists.
//!
//! Each build is a function of its own with `#[target_feature]`, so that what its body calls
//! `#[inline(always)]` is compiled for that instruction set: a closure handed to such a function
//! would be compiled once for the baseline and called. The builds are named, so that tests can
//! compare each with the baseline. Where the builds make the same operations in the same order
//! (no product fused: the code asks for no fused multiply-add), their results are equal bit for
//! bit.

/// Defines `fn name(arguments) -> output` that runs the first listed build whose instruction
/// sets the processor has, else the baseline:
///
/// ```ignore
/// multiversion! {
///     /// Documentation of the function.
///     pub fn name(a: &[f64], b: usize) -> f64 {
///         name_avx512 for ["avx512f"] => { body(a, b) }
///         name_avx2 for ["avx2", "fma"] => { body(a, b) }
///         baseline => { body(a, b) }
///     }
/// }
/// ```
///
/// Each named build is an `unsafe fn` with the same arguments, compiled with those target
/// features (x86-64 only): safe to call only where the processor has them.
macro_rules! multiversion {
    (
        $(#[$attribute:meta])*
        $visibility:vis fn $name:ident($($argument:ident: $type:ty),* $(,)?) $(-> $output:ty)? {
            $($builds:tt)*
        }
    ) => {
        $(#[$attribute])*
        $visibility fn $name($($argument: $type),*) $(-> $output)? {
            $crate::dispatch::multiversion!(@choose [$($argument),*] $($builds)*)
        }
        $crate::dispatch::multiversion!(
            @builds [($($argument: $type),*) $(-> $output)?] $($builds)*
        );
    };
    // the first build the processor has, tried in the order listed
    (@choose [$($argument:ident),*]
        $build:ident for [$($feature:tt),+] => $body:block $($rest:tt)*
    ) => {{
        #[cfg(target_arch = "x86_64")]
        if $(std::arch::is_x86_feature_detected!($feature))&&+ {
            // SAFETY: the processor has these instruction sets, just checked.
            return unsafe { $build($($argument),*) };
        }
        $crate::dispatch::multiversion!(@choose [$($argument),*] $($rest)*)
    }};
    (@choose [$($argument:ident),*] baseline => $body:block) => {
        $body
    };
    // each build, a function of its own
    (@builds [$($signature:tt)*]
        $build:ident for [$($feature:tt),+] => $body:block $($rest:tt)*
    ) => {
        #[doc = concat!("Built with ", $($feature, " "),+, "enabled; safe to call only where the processor has them.")]
        #[cfg(target_arch = "x86_64")]
        #[target_feature($(enable = $feature),+)]
        unsafe fn $build $($signature)* $body
        $crate::dispatch::multiversion!(@builds [$($signature)*] $($rest)*);
    };
    (@builds [$($signature:tt)*] baseline => $body:block) => {};
}

pub(crate) use multiversion;
