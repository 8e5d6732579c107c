//! Neighbour search: cell lists (cell ≥ half the search radius), CSR neighbour lists, parallel.
//!
//! Every particle gets its own full list (pairs stored both ways), so parallel loops over
//! particles write only their own particle: no atomics, and the result does not depend on
//! the thread count. Cost is O(N): each particle scans the 5^D cells around its own.
//! Periodic axes wrap the cell grid and use the minimum-image displacement ([`Domain`]).

use nalgebra::SVector;
use rayon::prelude::*;

/// Periodicity of the domain: the minimum-image displacement on periodic axes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Domain<const D: usize> {
    /// Per axis: `Some((min, max))` if periodic.
    pub periodic: [Option<(f64, f64)>; D],
}

impl<const D: usize> Default for Domain<D> {
    fn default() -> Self {
        Self { periodic: [None; D] }
    }
}

impl<const D: usize> Domain<D> {
    /// True if any axis is periodic.
    #[inline]
    pub fn is_periodic(&self) -> bool {
        self.periodic.iter().any(Option::is_some)
    }

    /// `r_a − r_b` with the minimum-image convention on periodic axes \[m\].
    #[inline(always)]
    pub fn displacement(&self, xa: &SVector<f64, D>, xb: &SVector<f64, D>) -> SVector<f64, D> {
        let mut d = xa - xb;
        for k in 0..D {
            if let Some((lo, hi)) = self.periodic[k] {
                // Wrapped positions differ by less than a period: the rounding (a libm call,
                // 14 % of a channel step when done for every pair) is rarely needed.
                let l = hi - lo;
                if d[k].abs() > 0.5 * l {
                    d[k] -= l * (d[k] / l).round();
                }
            }
        }
        d
    }

    /// Wraps a position into the periodic range on periodic axes.
    #[inline]
    pub fn wrap(&self, x: &mut SVector<f64, D>) {
        for k in 0..D {
            if let Some((lo, hi)) = self.periodic[k] {
                let l = hi - lo;
                x[k] = lo + (x[k] - lo).rem_euclid(l);
            }
        }
    }
}

/// Neighbour lists in compressed sparse row form: the neighbours of particle `a` are
/// `indices[offsets[a]..offsets[a + 1]]` (self excluded), in a fixed order.
#[derive(Debug, Clone, Default)]
pub struct NeighbourList {
    /// Row offsets, length N + 1.
    pub offsets: Vec<usize>,
    /// Column indices (neighbour particle indices).
    pub indices: Vec<u32>,
}

impl NeighbourList {
    /// Number of particles.
    pub fn len(&self) -> usize {
        self.offsets.len().saturating_sub(1)
    }

    /// True if there are no particles.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Neighbours of particle `a`.
    #[inline(always)]
    pub fn of(&self, a: usize) -> &[u32] {
        &self.indices[self.offsets[a]..self.offsets[a + 1]]
    }

    /// Total number of (directed) pairs.
    pub fn pairs(&self) -> usize {
        self.indices.len()
    }
}

/// Cell-list neighbour search with reusable scratch space (no allocation once warmed up).
#[derive(Debug, Clone)]
pub struct CellSearch<const D: usize> {
    radius: f64,
    domain: Domain<D>,
    origin: SVector<f64, D>,
    cell_size: SVector<f64, D>,
    dims: [usize; D],
    cell_of: Vec<u32>,
    cell_start: Vec<u32>,
    sorted: Vec<u32>,
    chunk_rows: Vec<Vec<u32>>,
    counts: Vec<u32>,
}

/// Cap on the cell grid: at most this many cells per particle.
const MAX_CELLS_PER_PARTICLE: usize = 8;

/// Cells per search radius: cells of at least `radius / REACH`, and the candidates of a
/// particle are the (2 REACH + 1)^D cells around its own. Half-radius cells (REACH = 2) scan
/// 6.25 r² instead of 9 r² in 2D (15.6 r³ instead of 27 r³ in 3D): about a third fewer
/// distance tests, for 5 instead of 3 contiguous row runs per row of cells in 2D.
const REACH: isize = 2;

/// Rows per parallel task when filling the lists.
const CHUNK: usize = 512;

impl<const D: usize> CellSearch<D> {
    /// A search for all pairs closer than `radius` \[m\] in `domain`.
    pub fn new(radius: f64, domain: Domain<D>) -> Self {
        Self {
            radius,
            domain,
            origin: SVector::zeros(),
            cell_size: SVector::repeat(radius),
            dims: [1; D],
            cell_of: Vec::new(),
            cell_start: Vec::new(),
            sorted: Vec::new(),
            chunk_rows: Vec::new(),
            counts: Vec::new(),
        }
    }

    /// Search radius \[m\].
    pub fn radius(&self) -> f64 {
        self.radius
    }

    /// Bins the particles into cells (counting sort, stable).
    fn bin(&mut self, x: &[SVector<f64, D>]) {
        let n = x.len();
        let mut lo = SVector::<f64, D>::repeat(f64::INFINITY);
        let mut hi = SVector::<f64, D>::repeat(f64::NEG_INFINITY);
        for p in x {
            lo = lo.inf(p);
            hi = hi.sup(p);
        }
        // Cells of at least radius / REACH; larger when the particles are spread so far
        // (a run blowing up) that the grid would exceed MAX_CELLS_PER_PARTICLE cells per
        // particle: the search stays correct, only slower, until the guard stops the run.
        let cell = self.radius / REACH as f64;
        let extent: f64 = (0..D)
            .map(|k| match self.domain.periodic[k] {
                Some((a, b)) => (b - a) / cell,
                None => (hi[k] - lo[k]) / cell + 1.0,
            })
            // An extent beyond f64 (particles ~1e308 m apart) counts as the largest one.
            .map(|c| {
                if c.is_finite() {
                    c.max(1.0)
                } else if c.is_nan() {
                    1.0
                } else {
                    f64::MAX
                }
            })
            .product();
        let limit = (MAX_CELLS_PER_PARTICLE * x.len().max(1)) as f64;
        let scale = if extent > limit { (extent / limit).powf(1.0 / D as f64) } else { 1.0 };
        let size = cell * scale;
        for k in 0..D {
            if let Some((a, b)) = self.domain.periodic[k] {
                // Whole number of cells per period, each at least `size`.
                let cells = ((b - a) / size).floor().max(1.0) as usize;
                self.dims[k] = cells;
                self.origin[k] = a;
                self.cell_size[k] = (b - a) / cells as f64;
            } else {
                let span = if (hi[k] - lo[k]).is_finite() { hi[k] - lo[k] } else { 0.0 };
                self.origin[k] = if lo[k].is_finite() { lo[k] } else { 0.0 };
                self.cell_size[k] = size;
                self.dims[k] = ((span / size).floor().min(limit) as usize).saturating_add(1);
            }
        }
        // A spread along one axis only (one particle flung far away) still exceeds the cap
        // after the isotropic scaling: shrink the longest axis. Particles beyond the last
        // cell are clamped into it, which keeps every pair within the radius at most REACH
        // cells apart (the search stays correct); periodic axes get wider cells instead.
        loop {
            let total: f64 = self.dims.iter().map(|&d| d as f64).product();
            if total <= limit {
                break;
            }
            let k = (0..D).max_by_key(|&k| self.dims[k]).unwrap_or(0);
            self.dims[k] = ((self.dims[k] as f64 * limit / total).floor() as usize).max(1);
            if let Some((a, b)) = self.domain.periodic[k] {
                self.cell_size[k] = (b - a) / self.dims[k] as f64;
            }
        }
        let ncells: usize = self.dims.iter().product();
        self.cell_of.resize(n, 0);
        let (origin, size, dims) = (self.origin, self.cell_size, self.dims);
        self.cell_of.par_iter_mut().zip(x.par_iter()).for_each(|(c, p)| {
            let mut id = 0usize;
            for k in (0..D).rev() {
                let i = (((p[k] - origin[k]) / size[k]).floor().max(0.0) as usize).min(dims[k] - 1);
                id = id * dims[k] + i;
            }
            *c = id as u32;
        });
        self.cell_start.clear();
        self.cell_start.resize(ncells + 1, 0);
        for &c in &self.cell_of {
            self.cell_start[c as usize + 1] += 1;
        }
        for c in 0..ncells {
            self.cell_start[c + 1] += self.cell_start[c];
        }
        self.sorted.resize(n, 0);
        self.counts.clear();
        self.counts.extend_from_slice(&self.cell_start[..ncells]);
        for (i, &c) in self.cell_of.iter().enumerate() {
            let slot = &mut self.counts[c as usize];
            self.sorted[*slot as usize] = i as u32;
            *slot += 1;
        }
    }

    /// A permutation `perm` (new index → old index) that orders particles by cell, for
    /// memory locality; apply it to every particle array. Borrowed from the search's own
    /// buffer (valid until its next call).
    pub fn cell_order(&mut self, x: &[SVector<f64, D>]) -> &[u32] {
        self.bin(x);
        &self.sorted
    }

    /// Builds the neighbour lists of all particles at positions `x` into `list`.
    pub fn build(&mut self, x: &[SVector<f64, D>], list: &mut NeighbourList) {
        self.build_rows(x, x.len(), list);
    }

    /// Builds the neighbour lists of the first `rows` particles of `x` (their neighbours
    /// taken among all of `x`) into `list`: boundary particles at the end of `x` are found
    /// as neighbours but get no row of their own.
    pub fn build_rows(&mut self, x: &[SVector<f64, D>], rows: usize, list: &mut NeighbourList) {
        self.bin(x);
        let n = rows.min(x.len());
        let nchunks = n.div_ceil(CHUNK);
        if self.chunk_rows.len() < nchunks {
            self.chunk_rows.resize_with(nchunks, Vec::new);
        }
        list.offsets.resize(n + 1, 0);
        let r2 = self.radius * self.radius;
        let mut chunk_rows = std::mem::take(&mut self.chunk_rows);
        let this = &*self;
        let fill = |c: usize, rows: &mut Vec<u32>, counts: &mut [usize]| {
            if this.domain.is_periodic() {
                this.fill_chunk(x, c * CHUNK, r2, rows, counts, |a, b| this.domain.displacement(a, b));
            } else {
                this.fill_chunk(x, c * CHUNK, r2, rows, counts, |a, b| a - b);
            }
        };
        chunk_rows[..nchunks]
            .par_iter_mut()
            .zip(list.offsets[1..].par_chunks_mut(CHUNK))
            .enumerate()
            .for_each(|(c, (rows, counts))| fill(c, rows, counts));
        list.offsets[0] = 0;
        for a in 0..n {
            list.offsets[a + 1] += list.offsets[a];
        }
        list.indices.resize(list.offsets[n], 0);
        copy_chunks(&chunk_rows[..nchunks], &mut list.indices);
        self.chunk_rows = chunk_rows;
    }

    /// The neighbour rows of particles `first..first + counts.len()` appended to `rows`,
    /// with each row's length in `counts`; `disp` is the displacement of the domain (the
    /// plain difference when nothing is periodic, so the hot loop has no per-axis test).
    ///
    /// Whether a candidate is within the radius is random from one to the next (about half
    /// are in 2D), so a branch per candidate mispredicts often: the candidates of a run are
    /// tested in groups of 64 into a bit mask without branches, and the set bits are then
    /// read off in order (the same neighbours in the same order as a plain filter).
    #[inline(always)]
    fn fill_chunk(
        &self,
        x: &[SVector<f64, D>],
        first: usize,
        r2: f64,
        rows: &mut Vec<u32>,
        counts: &mut [usize],
        disp: impl Fn(&SVector<f64, D>, &SVector<f64, D>) -> SVector<f64, D>,
    ) {
        rows.clear();
        for (k, count) in counts.iter_mut().enumerate() {
            let a = first + k;
            let xa = x[a];
            let before = rows.len();
            self.visit_candidates(&xa, |run| {
                for group in run.chunks(64) {
                    let mut mask = 0u64;
                    for (i, &b) in group.iter().enumerate() {
                        let d2 = disp(&xa, &x[b as usize]).norm_squared();
                        mask |= u64::from((d2 < r2) & (b as usize != a)) << i;
                    }
                    while mask != 0 {
                        rows.push(group[mask.trailing_zeros() as usize]);
                        mask &= mask - 1;
                    }
                }
            });
            *count = rows.len() - before;
        }
    }

    /// Calls `f` with runs of `sorted` that together hold every particle in the
    /// (2 REACH + 1)^D cells around `p` (each particle once), in the order of
    /// [`Self::visit_cells`].
    ///
    /// Axis 0 varies fastest in the cell id, so the (up to) 2 REACH + 1 cells of one row
    /// around `p` are consecutive ids and their particles one contiguous run of `sorted`:
    /// one range per row of cells ((2 REACH + 1)^(D−1) ranges) instead of one per cell.
    /// A row that wraps around a periodic axis 0 is not contiguous and goes cell by cell.
    #[inline]
    fn visit_candidates(&self, p: &SVector<f64, D>, mut f: impl FnMut(&[u32])) {
        let base = self.cell_index(p);
        let d0 = self.dims[0] as isize;
        let (lo0, hi0) = if self.domain.periodic[0].is_some() {
            if d0 < 2 * REACH + 1 || base[0] < REACH || base[0] + REACH >= d0 {
                return self.visit_cells(&base, f);
            }
            (base[0] - REACH, base[0] + REACH)
        } else {
            ((base[0] - REACH).max(0), (base[0] + REACH).min(d0 - 1))
        };
        let mut off = [-REACH; D];
        loop {
            let row = (1..D)
                .rev()
                .try_fold(0usize, |row, k| Some(row * self.dims[k] + self.axis_cell(k, base[k], off[k])?));
            if let Some(row) = row {
                let first = row * self.dims[0];
                let (s, e) = (
                    self.cell_start[first + lo0 as usize] as usize,
                    self.cell_start[first + hi0 as usize + 1] as usize,
                );
                f(&self.sorted[s..e]);
            }
            if !next_offset(&mut off, 1) {
                return;
            }
        }
    }

    /// The cell holding `p`, per axis (clamped into the grid).
    #[inline]
    fn cell_index(&self, p: &SVector<f64, D>) -> [isize; D] {
        let mut base = [0isize; D];
        for k in 0..D {
            base[k] = (((p[k] - self.origin[k]) / self.cell_size[k]).floor().max(0.0) as isize)
                .min(self.dims[k] as isize - 1);
        }
        base
    }

    /// Calls `f` with the particles of each of the (2 REACH + 1)^D cells around the cell
    /// `base`, cell by cell (axis 0 fastest; each cell once, also when a periodic axis has
    /// fewer than 2 REACH + 1 cells).
    fn visit_cells(&self, base: &[isize; D], mut f: impl FnMut(&[u32])) {
        let mut off = [-REACH; D];
        loop {
            let id = (0..D)
                .rev()
                .try_fold(0usize, |id, k| Some(id * self.dims[k] + self.axis_cell(k, base[k], off[k])?));
            if let Some(id) = id {
                let (s, e) = (self.cell_start[id] as usize, self.cell_start[id + 1] as usize);
                f(&self.sorted[s..e]);
            }
            if !next_offset(&mut off, 0) {
                return;
            }
        }
    }

    /// Index on axis `k` of the cell `base + off` (wrapped on a periodic axis), or `None`
    /// outside the grid, or where a periodic axis has fewer than 2 REACH + 1 cells and the
    /// offset would revisit a cell (only the first `dk` offsets, −REACH upward, are kept).
    #[inline(always)]
    fn axis_cell(&self, k: usize, base: isize, off: isize) -> Option<usize> {
        let dk = self.dims[k] as isize;
        let i = base + off;
        if self.domain.periodic[k].is_some() {
            if off >= dk - REACH {
                return None;
            }
            Some(i.rem_euclid(dk) as usize)
        } else if (0..dk).contains(&i) {
            Some(i as usize)
        } else {
            None
        }
    }
}

/// Copies the concatenation of `chunks` into `dst` (of their total length), the chunks in
/// parallel.
fn copy_chunks(chunks: &[Vec<u32>], dst: &mut [u32]) {
    if let [chunk] = chunks {
        dst.copy_from_slice(chunk);
    } else if chunks.len() > 1 {
        let mid = chunks.len() / 2;
        let (l, r) = dst.split_at_mut(chunks[..mid].iter().map(Vec::len).sum());
        rayon::join(|| copy_chunks(&chunks[..mid], l), || copy_chunks(&chunks[mid..], r));
    }
}

/// Advances the cell offsets `off[from..]` through {−REACH, …, REACH}^(D−from), axis `from`
/// fastest (an odometer); false once every combination was visited.
#[inline(always)]
fn next_offset<const D: usize>(off: &mut [isize; D], from: usize) -> bool {
    for o in &mut off[from..] {
        *o += 1;
        if *o <= REACH {
            return true;
        }
        *o = -REACH;
    }
    false
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn brute<const D: usize>(x: &[SVector<f64, D>], r: f64, dom: &Domain<D>) -> Vec<Vec<u32>> {
        (0..x.len())
            .map(|a| {
                (0..x.len())
                    .filter(|&b| b != a && dom.displacement(&x[a], &x[b]).norm() < r)
                    .map(|b| b as u32)
                    .collect()
            })
            .collect()
    }

    fn check<const D: usize>(n: usize, r: f64, dom: Domain<D>, seed: u64) {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let x: Vec<SVector<f64, D>> =
            (0..n).map(|_| SVector::from_fn(|_, _| rng.random_range(0.0..1.0))).collect();
        let mut search = CellSearch::new(r, dom);
        let mut list = NeighbourList::default();
        search.build(&x, &mut list);
        let want = brute(&x, r, &dom);
        for (a, want) in want.iter().enumerate() {
            let mut got = list.of(a).to_vec();
            got.sort_unstable();
            assert_eq!(&got, want, "particle {a}");
        }
    }

    #[test]
    fn matches_brute_force_2d_and_3d() {
        for seed in 0..4 {
            check::<2>(700, 0.07, Domain::default(), seed);
            check::<3>(600, 0.15, Domain::default(), seed);
        }
    }

    #[test]
    fn matches_brute_force_with_periodic_axes() {
        let per = Domain { periodic: [Some((0.0, 1.0)), None] };
        check::<2>(800, 0.09, per, 7);
        let per3 = Domain { periodic: [Some((0.0, 1.0)), None, Some((0.0, 1.0))] };
        check::<3>(500, 0.2, per3, 8);
        // Fewer than 2 REACH + 1 cells per period (4, and 2).
        check::<2>(200, 0.45, per, 9);
        check::<2>(200, 0.9, per, 10);
    }

    /// The row ranges give each list in exactly the cell-by-cell order (so the sums over
    /// neighbours, and the results, are bit for bit those of the cell-by-cell visit).
    #[test]
    fn row_ranges_keep_the_cell_by_cell_order() {
        fn same_order<const D: usize>(dom: Domain<D>, r: f64, seed: u64) {
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            let x: Vec<SVector<f64, D>> =
                (0..600).map(|_| SVector::from_fn(|_, _| rng.random_range(0.0..1.0))).collect();
            let mut search = CellSearch::new(r, dom);
            let mut list = NeighbourList::default();
            search.build(&x, &mut list);
            for (a, xa) in x.iter().enumerate() {
                let mut want = Vec::new();
                search.visit_cells(&search.cell_index(xa), |cell| {
                    for &b in cell {
                        if b as usize != a && dom.displacement(xa, &x[b as usize]).norm_squared() < r * r {
                            want.push(b);
                        }
                    }
                });
                assert_eq!(list.of(a), &want[..], "particle {a}");
            }
        }
        same_order::<2>(Domain::default(), 0.07, 1);
        same_order::<2>(Domain { periodic: [Some((0.0, 1.0)), None] }, 0.09, 2);
        same_order::<2>(Domain { periodic: [None, Some((0.0, 1.0))] }, 0.09, 3);
        same_order::<2>(Domain { periodic: [Some((0.0, 1.0)), None] }, 0.45, 4);
        same_order::<3>(Domain { periodic: [Some((0.0, 1.0)), None, Some((0.0, 1.0))] }, 0.2, 5);
    }

    #[test]
    fn far_flung_particles_do_not_explode_the_grid() {
        // A blown-up particle far away: the grid is coarsened, the pairs stay right.
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let mut x: Vec<SVector<f64, 2>> =
            (0..400).map(|_| SVector::from_fn(|_, _| rng.random_range(0.0..1.0))).collect();
        x.push(SVector::<f64, 2>::from([1e12, -1e12]));
        let mut search = CellSearch::new(0.08, Domain::default());
        let mut list = NeighbourList::default();
        search.build(&x, &mut list);
        let want = brute(&x, 0.08, &Domain::default());
        for (a, want) in want.iter().enumerate() {
            let mut got = list.of(a).to_vec();
            got.sort_unstable();
            assert_eq!(&got, want);
        }
        // At most MAX_CELLS_PER_PARTICLE cells per particle, plus one layer per axis.
        assert!(
            search.cell_start.len() <= 2 * MAX_CELLS_PER_PARTICLE * x.len(),
            "{}",
            search.cell_start.len()
        );
    }

    #[test]
    fn cell_order_is_a_permutation() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let x: Vec<SVector<f64, 2>> =
            (0..300).map(|_| SVector::from_fn(|_, _| rng.random_range(-1.0..1.0))).collect();
        let mut s = CellSearch::new(0.1, Domain::default());
        let mut p = s.cell_order(&x).to_vec();
        p.sort_unstable();
        assert!(p.iter().enumerate().all(|(i, &v)| v as usize == i));
    }
}
