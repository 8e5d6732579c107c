//! The scheme abstraction: a particle method builds its particles, its own data and its
//! stage list from the scene, and owns its time-step rule ([`Scheme`]); the run driver and
//! the profiler step any scheme through one object-safe view of it ([`Method`]), so they
//! know no scheme (the scene's scheme is matched once, in [`crate::registry`]).
//!
//! A scheme's data is the shared [`State`] (particles, neighbour lists and pair cache,
//! boundary bookkeeping) plus its own ([`Scheme::Own`]: per-particle fields declared with
//! [`crate::particle_fields!`], which the reorder permutes and the profiler saves, and any
//! per-step data such as the PPE system). A method with a different state (OTM's nodes
//! beside its material points) keeps it in `Own`.

use crate::error::{Cause, SceneError};
use crate::fields::{ColumnRef, Columns, Extent, Field, Fields};
use crate::kernel::{Kernel, Scaled};
use crate::scene::Scene;
use crate::stage::{Stage, StepContext};
use crate::state::{Flux, InletLink, State};

/// The coefficients of the scene's adaptive time step (`time.step.adaptive`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Adaptive {
    /// Advective (CFL) coefficient.
    pub cfl: f64,
    /// Viscous coefficient.
    pub viscous: f64,
    /// Largest step \[s\].
    pub max: f64,
}

/// A particle method.
pub trait Scheme<const D: usize>: Send + std::fmt::Debug + Sized + 'static {
    /// The scheme's own data beside the shared [`State`].
    type Own: Fields<D> + Send + std::fmt::Debug + 'static;

    /// Builds the particles, the scheme's own data and its stage list for `scene` (a
    /// stage the scene does not need is not built) with `kernel`.
    fn build<K: Kernel>(scene: &Scene, kernel: Scaled<K, D>) -> Result<Composed<D, Self>, SceneError>;

    /// The largest stable step \[s\] at this state under the adaptive rule `rule`: the
    /// smallest of the scheme's stability limits.
    fn stable_step(&self, rule: Adaptive, state: &State<D>, own: &Self::Own) -> f64;

    /// The radius of the scheme's neighbour lists \[m\] (the guard's overstep distance and
    /// neighbour-count band): the kernel support `kernel_support` unless the scheme
    /// searches farther.
    fn reach(&self, kernel_support: f64) -> f64 {
        kernel_support
    }
}

/// A scheme with its state and stages: what a [`Method`] is.
#[derive(Debug)]
pub struct Composed<const D: usize, S: Scheme<D>> {
    /// The scheme (its parameters).
    pub scheme: S,
    /// The shared state.
    pub state: State<D>,
    /// The scheme's own data.
    pub own: S::Own,
    /// The stages of one step, in order.
    pub stages: Vec<Box<dyn Stage<D, S::Own>>>,
}

/// The arrays a [`Method`] saves and restores: its declared per-particle fields (shared
/// and own) and the open-boundary bookkeeping that changes with them.
#[derive(Debug, Clone, Default)]
pub struct SavedState<const D: usize> {
    particles: Columns<D>,
    own: Columns<D>,
    fluid: usize,
    buffer: usize,
    flux: Flux,
    inlet: InletLink,
}

impl<const D: usize> SavedState<D> {
    /// Number of fluid particles saved.
    pub fn fluid(&self) -> usize {
        self.fluid
    }
}

/// What the run driver and the profiler see of a composed scheme (object safe).
pub trait Method<const D: usize>: Send + std::fmt::Debug {
    /// The shared state.
    fn state(&self) -> &State<D>;
    /// The shared state, writable (tests and tools that perturb a run).
    fn state_mut(&mut self) -> &mut State<D>;
    /// The scheme's own data, for inspection (downcast to its [`Scheme::Own`]).
    fn own(&self) -> &dyn std::any::Any;
    /// Number of stages of one step.
    fn stage_count(&self) -> usize;
    /// Name of stage `i` (as in `summary.json`); panics if `i >= stage_count()`.
    fn stage_name(&self, i: usize) -> &'static str;
    /// Runs stage `i` of the step `ctx`; panics if `i >= stage_count()`.
    fn run_stage(&mut self, i: usize, ctx: &StepContext) -> Result<(), Cause>;
    /// The scheme's largest stable step \[s\] under `rule` ([`Scheme::stable_step`]).
    fn stable_step(&self, rule: Adaptive) -> f64;
    /// Copies the declared fields into `saved` (`extent`: all of them, or what a frame
    /// of the fluid needs), reusing its storage.
    fn save(&self, saved: &mut SavedState<D>, extent: Extent);
    /// Puts back what [`Method::save`] saved with [`Extent::All`].
    fn restore(&mut self, saved: &SavedState<D>);
    /// Calls `f` with every declared field, shared then own, of the current state or (with
    /// `saved`) of a saved one.
    fn visit_fields(&self, saved: Option<&SavedState<D>>, f: &mut dyn FnMut(Field<ColumnRef<'_, D>>));
}

impl<const D: usize, S: Scheme<D>> Method<D> for Composed<D, S> {
    fn state(&self) -> &State<D> {
        &self.state
    }

    fn state_mut(&mut self) -> &mut State<D> {
        &mut self.state
    }

    fn own(&self) -> &dyn std::any::Any {
        &self.own
    }

    fn stage_count(&self) -> usize {
        self.stages.len()
    }

    fn stage_name(&self, i: usize) -> &'static str {
        self.stages[i].name()
    }

    fn run_stage(&mut self, i: usize, ctx: &StepContext) -> Result<(), Cause> {
        self.stages[i].run(&mut self.state, &mut self.own, ctx)
    }

    fn stable_step(&self, rule: Adaptive) -> f64 {
        self.scheme.stable_step(rule, &self.state, &self.own)
    }

    fn save(&self, saved: &mut SavedState<D>, extent: Extent) {
        let s = &self.state;
        saved.particles.save(&s.particles, extent);
        saved.own.save(&self.own, extent);
        saved.fluid = s.particles.fluid;
        if extent == Extent::All {
            saved.buffer = s.buffer;
            saved.flux = s.flux;
            saved.inlet.clone_from(&s.inlet);
        }
    }

    fn restore(&mut self, saved: &SavedState<D>) {
        let s = &mut self.state;
        saved.particles.restore(&mut s.particles);
        saved.own.restore(&mut self.own);
        s.particles.fluid = saved.fluid;
        s.buffer = saved.buffer;
        s.flux = saved.flux;
        s.inlet.clone_from(&saved.inlet);
    }

    fn visit_fields(&self, saved: Option<&SavedState<D>>, f: &mut dyn FnMut(Field<ColumnRef<'_, D>>)) {
        match saved {
            None => {
                self.state.particles.visit(f);
                self.own.visit(f);
            }
            Some(saved) => {
                saved.particles.visit_as(&self.state.particles, f);
                saved.own.visit_as(&self.own, f);
            }
        }
    }
}
