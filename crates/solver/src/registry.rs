//! The one place that maps a scene's scheme and kernel to their implementations: a new
//! scheme is one module implementing [`Scheme`] plus one line in [`compose`].

use crate::error::SceneError;
use crate::isph::Isph;
use crate::kernel::{CubicSpline, Kernel, Scaled, WendlandC2};
use crate::mps::Mps;
use crate::otm::scheme::Otm;
use crate::probes::Weight;
use crate::scene::{KernelKind, Scene, Scheme as SceneScheme};
use crate::scheme::{Method, Scheme};
use crate::wcsph::Wcsph;

/// A composed scheme and what the driver needs of its kernel.
#[derive(Debug)]
pub struct Built<const D: usize> {
    /// The scheme with its state and stages.
    pub method: Box<dyn Method<D>>,
    /// The kernel, for the probes' kernel-weighted averages.
    pub weight: Weight,
    /// The radius of the scheme's neighbour lists \[m\] (the kernel support, or farther:
    /// [`Scheme::reach`]).
    pub support: f64,
}

/// Builds the scheme the scene names, with the scene's kernel.
pub fn compose<const D: usize>(scene: &Scene) -> Result<Built<D>, SceneError> {
    match &scene.scheme {
        SceneScheme::Isph(_) => compose_with::<D, Isph>(scene),
        SceneScheme::Wcsph(_) => compose_with::<D, Wcsph>(scene),
        SceneScheme::Mps(_) => compose_with::<D, Mps>(scene),
        SceneScheme::Otm(_) => compose_with::<D, Otm>(scene),
    }
}

/// Builds scheme `S` for `scene`, dispatching on the scene's kernel.
pub fn compose_with<const D: usize, S: Scheme<D>>(scene: &Scene) -> Result<Built<D>, SceneError> {
    match scene.kernel.kind {
        KernelKind::CubicSpline => with_kernel::<D, S, CubicSpline>(scene),
        KernelKind::WendlandC2 => with_kernel::<D, S, WendlandC2>(scene),
    }
}

fn with_kernel<const D: usize, S: Scheme<D>, K: Kernel>(scene: &Scene) -> Result<Built<D>, SceneError> {
    let kernel = Scaled::<K, D>::new(scene.h());
    let composed = S::build(scene, kernel)?;
    let support = composed.scheme.reach(kernel.support);
    Ok(Built {
        method: Box::new(composed),
        weight: Weight { w: Box::new(move |r| kernel.w(r)), support: kernel.support },
        support,
    })
}
