//! Density-based clustering of pooled poles and classification of the clusters.

use std::collections::{HashMap, HashSet};

use serde::{Deserialize, Serialize};

use crate::shapes::{mac, mean_shape};
use crate::stats::{mean_std, median, percentile_sorted};
use crate::{ClusterParams, InvariantMode, ModalError, ModeClass, PoleObservation};

/// Full result of [`analyse_poles`]: the clusters plus the per-pole assignment, for plotting
/// (e.g. colouring a stabilisation diagram by cluster).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ModalAnalysis {
    /// All clusters (Structural, PeriodicDisturbance and Spurious), sorted by ascending
    /// `frequency_hz`.
    pub modes: Vec<InvariantMode>,
    /// For every input pole (same order as the input slice), the index into `modes` of its
    /// cluster, or `None` (ignored by the filters, noise, or a duplicate of its fit in the cluster).
    pub labels: Vec<Option<usize>>,
    /// Number of poles that passed the frequency/damping filters and took part in the clustering.
    pub n_used: usize,
    /// Number of poles ignored by the filters (`freq_min_hz`, `freq_max_hz`, `max_damping_ratio`,
    /// negative damping).
    pub n_ignored: usize,
    /// `n_records * orders.len() * n_channels` (distinct channels among the used poles).
    pub n_fits: usize,
    /// Core threshold actually used: `max(min_points, ceil(min_density_share * n_fits))` poles.
    pub core_threshold: usize,
}

/// Pool the poles of all records, channels and model orders and return the clusters (invariant
/// modes, periodic disturbances and spurious clusters, flagged by `class`), sorted by frequency.
///
/// * `n_records`: number of records the poles come from (record indices must be `< n_records`);
///   records that produced no pole still count in `record_share`.
/// * `orders`: the model orders that were fitted (every pole's order must be listed; duplicates
///   are ignored); orders that produced no pole still count in `order_share`.
///
/// Empty `poles` gives `Ok(vec![])`. Errors: non-finite frequency/damping (with the pole index),
/// record or order out of range, `n_records == 0` or empty `orders` with poles, invalid params.
/// Never panics.
pub fn find_invariant_modes(
    poles: &[PoleObservation],
    n_records: usize,
    orders: &[usize],
    p: &ClusterParams,
) -> Result<Vec<InvariantMode>, ModalError> {
    Ok(analyse_poles(poles, n_records, orders, p)?.modes)
}

/// Same as [`find_invariant_modes`] but also returns the per-pole cluster labels and counts.
pub fn analyse_poles(
    poles: &[PoleObservation],
    n_records: usize,
    orders: &[usize],
    p: &ClusterParams,
) -> Result<ModalAnalysis, ModalError> {
    p.validate()?;
    if poles.is_empty() {
        return Ok(ModalAnalysis {
            modes: Vec::new(),
            labels: Vec::new(),
            n_used: 0,
            n_ignored: 0,
            n_fits: 0,
            core_threshold: p.min_points,
        });
    }
    let orders = checked_orders(poles, n_records, orders)?;
    let metric = Metric::new(p);
    let (mut pts, n_channels) = scaled_points(poles, p, &metric);
    let n_used = pts.len();
    let n_fits = n_records
        .saturating_mul(orders.len())
        .saturating_mul(n_channels);
    let core_threshold = p
        .min_points
        .max((p.min_density_share * n_fits as f64).ceil() as usize);
    let mut out = ModalAnalysis {
        modes: Vec::new(),
        labels: vec![None; poles.len()],
        n_used,
        n_ignored: poles.len() - n_used,
        n_fits,
        core_threshold,
    };
    if pts.is_empty() {
        return Ok(out);
    }
    let (cells, cell_list) = sort_into_cells(&mut pts);
    let grid = Grid {
        pts: &pts,
        cells,
        metric,
    };
    // 1. Core poles; 2. connected core poles; 3. border poles to their nearest core neighbour.
    let core = core_flags(&grid, &cell_list, core_threshold);
    let mut uf = connect_cores(&grid, &cell_list, &core);
    let members = cluster_members(&grid, &core, &mut uf);
    // 4. Summarise each cluster.
    let mut clusters: Vec<(InvariantMode, Vec<usize>)> = members
        .into_values()
        .map(|m| summarise(&pts, &m, poles, n_records, orders.len(), p, &metric))
        .collect();
    clusters.sort_by(|a, b| {
        a.0.frequency_hz
            .total_cmp(&b.0.frequency_hz)
            .then(a.0.damping_ratio.total_cmp(&b.0.damping_ratio))
    });
    for (k, (mode, kept)) in clusters.into_iter().enumerate() {
        for idx in kept {
            out.labels[idx] = Some(k);
        }
        out.modes.push(mode);
    }
    Ok(out)
}

/// Checks `n_records` and the poles against the records and orders; returns the orders sorted
/// and deduplicated.
fn checked_orders(
    poles: &[PoleObservation],
    n_records: usize,
    orders: &[usize],
) -> Result<Vec<usize>, ModalError> {
    if n_records == 0 {
        return Err(ModalError::EmptySupport {
            what: "n_records",
            n_poles: poles.len(),
        });
    }
    let mut orders: Vec<usize> = orders.to_vec();
    orders.sort_unstable();
    orders.dedup();
    if orders.is_empty() {
        return Err(ModalError::EmptySupport {
            what: "orders",
            n_poles: poles.len(),
        });
    }
    validate_poles(poles, n_records, &orders)?;
    Ok(orders)
}

/// The poles that pass the frequency/damping filters, mapped to the scaled plane, and the number
/// of distinct channels among them.
fn scaled_points(
    poles: &[PoleObservation],
    p: &ClusterParams,
    metric: &Metric,
) -> (Vec<Pt>, usize) {
    let lu = metric.lu;
    let mut pts: Vec<Pt> = Vec::with_capacity(poles.len());
    let mut channel_ids: HashMap<&str, usize> = HashMap::new();
    for (i, pole) in poles.iter().enumerate() {
        let f = pole.frequency_hz;
        let z = pole.damping_ratio;
        if !(f >= p.freq_min_hz
            && f <= p.freq_max_hz.unwrap_or(f64::INFINITY)
            && z >= 0.0
            && z <= p.max_damping_ratio)
        {
            continue;
        }
        let n_ch = channel_ids.len();
        let ch = *channel_ids.entry(pole.channel.as_str()).or_insert(n_ch);
        let u = f.ln() / lu;
        let zc = z.max(p.min_damping_ratio);
        let v = zc.log10() / p.log_damping_tol;
        // Largest frequency scale any neighbour can have: a neighbour's damping is at most
        // 10^log_damping_tol times this one's (and at most max_damping_ratio).
        let z_nb =
            (zc * 10f64.powf(0.5 * p.log_damping_tol)).min((zc * p.max_damping_ratio).sqrt());
        let reach_u = ((freq_scale(z_nb, p) / lu) * CELLS_PER_UNIT).ceil() as i64;
        pts.push(Pt {
            u,
            v,
            zeta: zc,
            reach_u: reach_u.max(REACH),
            cell: (
                (u * CELLS_PER_UNIT).floor() as i64,
                (v * CELLS_PER_UNIT).floor() as i64,
            ),
            idx: i,
            ch,
            shape: pole.shape.clone(),
        });
    }
    (pts, channel_ids.len())
}

/// Sorts the points by grid cell (side 1/sqrt(2): any two poles in one cell are neighbours) and
/// returns each cell's range of points, by cell and in order.
fn sort_into_cells(pts: &mut [Pt]) -> (Cells, Vec<(usize, usize)>) {
    pts.sort_by(|a, b| a.cell.cmp(&b.cell).then(a.idx.cmp(&b.idx)));
    let mut cells: Cells = HashMap::new();
    let mut cell_list: Vec<(usize, usize)> = Vec::new();
    let mut start = 0;
    for k in 1..=pts.len() {
        if k == pts.len() || pts[k].cell != pts[start].cell {
            cells.insert(pts[start].cell, (start, k));
            cell_list.push((start, k));
            start = k;
        }
    }
    (cells, cell_list)
}

/// Core poles: at least `core_threshold` neighbours (a cell holding that many poles is all core,
/// unless shapes can make cell-mates strangers).
fn core_flags(grid: &Grid<'_>, cell_list: &[(usize, usize)], core_threshold: usize) -> Vec<bool> {
    let mut core = vec![false; grid.pts.len()];
    let cells_are_cliques = !grid.metric.uses_shapes(grid.pts);
    for &(a, b) in cell_list {
        for (i, c) in core.iter_mut().enumerate().take(b).skip(a) {
            *c = (cells_are_cliques && b - a >= core_threshold)
                || grid.count_neighbours_upto(i, core_threshold) >= core_threshold;
        }
    }
    core
}

/// Connects core poles that are neighbours (union-find): all core poles of a cell together, then
/// one neighbouring core pair per pair of cells is enough.
fn connect_cores(grid: &Grid<'_>, cell_list: &[(usize, usize)], core: &[bool]) -> UnionFind {
    let pts = grid.pts;
    let mut uf = UnionFind::new(pts.len());
    let mut first_core: HashMap<(i64, i64), usize> = HashMap::new();
    let cells_are_cliques = !grid.metric.uses_shapes(pts);
    for &(a, b) in cell_list {
        if let Some(f) = (a..b).find(|&i| core[i]) {
            if cells_are_cliques {
                for i in (f + 1..b).filter(|&i| core[i]) {
                    uf.union(f, i);
                }
            } else {
                for i in (f..b).filter(|&i| core[i]) {
                    for j in (i + 1..b).filter(|&j| core[j]) {
                        if grid.metric.dist2(&pts[i], &pts[j]) <= 1.0 {
                            uf.union(i, j);
                        }
                    }
                }
            }
            first_core.insert(pts[f].cell, f);
        }
    }
    for &(a, b) in cell_list {
        let Some(&fa) = first_core.get(&pts[a].cell) else {
            continue;
        };
        let c = pts[a].cell;
        let reach = pts[a..b].iter().map(|q| q.reach_u).max().unwrap_or(REACH);
        for dx in -reach..=reach {
            for dy in -REACH..=REACH {
                let d = (c.0 + dx, c.1 + dy);
                if d <= c {
                    continue; // each unordered pair of cells once
                }
                let Some(&fd) = first_core.get(&d) else {
                    continue;
                };
                if cells_are_cliques && uf.find(fa) == uf.find(fd) {
                    continue;
                }
                let Some(&(da, db)) = grid.cells.get(&d) else {
                    continue;
                };
                'pairs: for i in (a..b).filter(|&i| core[i]) {
                    for j in (da..db).filter(|&j| core[j]) {
                        if grid.metric.dist2(&pts[i], &pts[j]) <= 1.0 {
                            uf.union(i, j);
                            if cells_are_cliques {
                                break 'pairs;
                            }
                        }
                    }
                }
            }
        }
    }
    uf
}

/// Members (point indices) of every cluster, keyed by its union-find root: core poles by their
/// component, border poles by the component of their nearest core neighbour.
fn cluster_members(
    grid: &Grid<'_>,
    core: &[bool],
    uf: &mut UnionFind,
) -> HashMap<usize, Vec<usize>> {
    let n = grid.pts.len();
    let mut root_of: Vec<Option<usize>> = vec![None; n];
    for i in 0..n {
        if core[i] {
            root_of[i] = Some(uf.find(i));
        } else {
            let mut best: Option<(f64, usize)> = None;
            grid.for_each_neighbour(i, |j, d2| {
                if core[j] && best.map_or(true, |(bd, _)| d2 < bd) {
                    best = Some((d2, j));
                }
            });
            if let Some((_, j)) = best {
                root_of[i] = Some(uf.find(j));
            }
        }
    }
    let mut members: HashMap<usize, Vec<usize>> = HashMap::new();
    for (i, r) in root_of.iter().enumerate() {
        if let Some(r) = r {
            members.entry(*r).or_default().push(i);
        }
    }
    members
}

fn validate_poles(
    poles: &[PoleObservation],
    n_records: usize,
    orders: &[usize],
) -> Result<(), ModalError> {
    for (index, pole) in poles.iter().enumerate() {
        crate::types::check_finite(pole, index)?;
        if pole.record >= n_records {
            let needed = poles.iter().map(|q| q.record).max().unwrap_or(0) + 1;
            return Err(ModalError::RecordOutOfRange {
                index,
                record: pole.record,
                n_records,
                needed,
            });
        }
        if orders.binary_search(&pole.order).is_err() {
            let orders_desc = match (orders.first(), orders.last()) {
                (Some(a), Some(b)) => format!("{} orders from {} to {}", orders.len(), a, b),
                _ => "empty".to_string(),
            };
            return Err(ModalError::OrderNotListed {
                index,
                order: pole.order,
                orders_desc,
            });
        }
    }
    Ok(())
}

/// Dedup per fit, compute statistics and class. Returns the mode and the kept input indices.
fn summarise(
    pts: &[Pt],
    members: &[usize],
    poles: &[PoleObservation],
    n_records: usize,
    n_orders: usize,
    p: &ClusterParams,
    metric: &Metric,
) -> (InvariantMode, Vec<usize>) {
    let kept = nearest_per_fit(pts, members, poles, p, metric);
    let freqs: Vec<f64> = kept.iter().map(|&i| poles[i].frequency_hz).collect();
    let mut damps: Vec<f64> = kept.iter().map(|&i| poles[i].damping_ratio).collect();
    damps.sort_by(f64::total_cmp);
    let (f_mean, f_std) = mean_std(&freqs);
    let (record_share, order_share) = support(&kept, poles, n_records, n_orders, p);
    let channels = distinct(kept.iter().map(|&i| poles[i].channel.clone()));
    let roles = distinct(kept.iter().filter_map(|&i| poles[i].role));
    let damping_ratio = percentile_sorted(&damps, 0.5);
    let supported =
        (n_records <= 1 || record_share >= p.min_record_share) && order_share >= p.min_order_share;
    let class = if !supported {
        ModeClass::Spurious
    } else if damping_ratio < p.disturbance_damping_max
        && f_std < p.disturbance_freq_spread_max * f_mean
    {
        ModeClass::PeriodicDisturbance
    } else {
        ModeClass::Structural
    };
    let (shape, shape_mac) = shape_stats(&kept, poles);
    let mode = InvariantMode {
        frequency_hz: f_mean,
        frequency_std_hz: f_std,
        damping_ratio,
        damping_iqr: (
            percentile_sorted(&damps, 0.25),
            percentile_sorted(&damps, 0.75),
        ),
        order_share,
        record_share,
        n_poles: kept.len(),
        channels,
        roles,
        min_order: kept.iter().map(|&i| poles[i].order).min().unwrap_or(0),
        class,
        line_kurtosis: None,
        shape,
        shape_mac,
        uncertainty: None,
    };
    (mode, kept)
}

/// A cluster's mean shape and the (median, lowest) MAC of its poles' shapes with it.
type ShapeStats = (Option<Vec<[f64; 2]>>, Option<(f64, f64)>);

/// Mean shape of the kept poles that carry one (all of one length), and the median and lowest
/// MAC of their shapes with it.
fn shape_stats(kept: &[usize], poles: &[PoleObservation]) -> ShapeStats {
    let shapes: Vec<&[[f64; 2]]> = kept
        .iter()
        .filter_map(|&i| poles[i].shape.as_deref())
        .collect();
    let Some(mean) = mean_shape(&shapes) else {
        return (None, None);
    };
    let mut macs: Vec<f64> = shapes.iter().map(|s| mac(s, &mean)).collect();
    macs.sort_by(f64::total_cmp);
    let lowest = macs.first().copied().unwrap_or(0.0);
    (Some(mean), Some((median(&macs), lowest)))
}

/// At most one pole per fit (record, channel, order) of the cluster `members`: the nearest to the
/// cluster centre (median of u and v), ties to the lower input index. Returns the kept input
/// indices, ascending.
fn nearest_per_fit(
    pts: &[Pt],
    members: &[usize],
    poles: &[PoleObservation],
    p: &ClusterParams,
    metric: &Metric,
) -> Vec<usize> {
    let cu = median(&members.iter().map(|&i| pts[i].u).collect::<Vec<_>>());
    let cv = median(&members.iter().map(|&i| pts[i].v).collect::<Vec<_>>());
    // Frequency scale at the centre's damping (constant within the cluster).
    let cs = metric.scale(
        10f64.powf(cv * p.log_damping_tol),
        10f64.powf(cv * p.log_damping_tol),
    );
    let mut best: HashMap<(usize, usize, usize), (f64, usize)> = HashMap::new();
    for &i in members {
        let pt = &pts[i];
        let pole = &poles[pt.idx];
        let d2 = ((pt.u - cu) * cs).powi(2) + (pt.v - cv).powi(2);
        let key = (pole.record, pt.ch, pole.order);
        match best.get(&key) {
            Some(&(bd, bidx)) if bd < d2 || (bd == d2 && bidx < pt.idx) => {}
            _ => {
                best.insert(key, (d2, pt.idx));
            }
        }
    }
    let mut kept: Vec<usize> = best.values().map(|&(_, idx)| idx).collect();
    kept.sort_unstable();
    kept
}

/// Support of a cluster (kept input indices): the share of records with at least
/// `record_min_order_share` of the orders, and the share of (record, order) fits present.
fn support(
    kept: &[usize],
    poles: &[PoleObservation],
    n_records: usize,
    n_orders: usize,
    p: &ClusterParams,
) -> (f64, f64) {
    let rec_orders: HashSet<(usize, usize)> = kept
        .iter()
        .map(|&i| (poles[i].record, poles[i].order))
        .collect();
    let mut orders_per_record: HashMap<usize, usize> = HashMap::new();
    for &(r, _) in &rec_orders {
        *orders_per_record.entry(r).or_insert(0) += 1;
    }
    let min_orders = ((p.record_min_order_share * n_orders as f64).ceil() as usize).max(1);
    let n_supporting = orders_per_record
        .values()
        .filter(|&&n| n >= min_orders)
        .count();
    let record_share = n_supporting as f64 / n_records as f64;
    let order_share = rec_orders.len() as f64 / (n_records as f64 * n_orders as f64);
    (record_share, order_share)
}

/// The distinct values, sorted.
fn distinct<T: Ord>(values: impl Iterator<Item = T>) -> Vec<T> {
    let mut v: Vec<T> = values.collect();
    v.sort();
    v.dedup();
    v
}

/// Grid cells per unit of the scaled plane: side 1/sqrt(2), so a cell's diagonal is 1.
const CELLS_PER_UNIT: f64 = std::f64::consts::SQRT_2;
/// Neighbouring cells to search on each side in `v`, and at least in `u` (ceil(sqrt(2)) = 2).
const REACH: i64 = 2;

/// Relative frequency neighbourhood, as a log-frequency width, for a pair of poles whose
/// geometric-mean damping ratio is `zeta`: `ln(1 + max(freq_tol_rel, freq_tol_per_damping * zeta))`.
fn freq_scale(zeta: f64, p: &ClusterParams) -> f64 {
    (1.0 + p.freq_tol_rel.max(p.freq_tol_per_damping * zeta)).ln()
}

/// The neighbour metric: `u` is in units of `ln(1 + freq_tol_rel)`; the frequency difference is
/// rescaled by the damping-dependent width of the pair.
#[derive(Clone, Copy)]
struct Metric {
    lu: f64,
    per_damping: f64,
    min_rel: f64,
    shape_tol: f64,
}

impl Metric {
    fn new(p: &ClusterParams) -> Self {
        Metric {
            lu: (1.0 + p.freq_tol_rel).ln(),
            per_damping: p.freq_tol_per_damping,
            min_rel: p.freq_tol_rel,
            shape_tol: p.shape_tol,
        }
    }

    /// True when poles carry shapes that enter the distance: then two poles of one grid cell
    /// need not be neighbours.
    fn uses_shapes(&self, pts: &[Pt]) -> bool {
        self.shape_tol > 0.0 && pts.iter().any(|p| p.shape.is_some())
    }

    /// Factor (<= 1) applied to a `u` difference for poles of damping ratios `za`, `zb`.
    fn scale(&self, za: f64, zb: f64) -> f64 {
        let rel = self.min_rel.max(self.per_damping * (za * zb).sqrt());
        self.lu / (1.0 + rel).ln()
    }
    fn dist2(&self, a: &Pt, b: &Pt) -> f64 {
        let du = (a.u - b.u) * self.scale(a.zeta, b.zeta);
        let d2 = du * du + (a.v - b.v) * (a.v - b.v);
        match (&a.shape, &b.shape) {
            (Some(sa), Some(sb)) if self.shape_tol > 0.0 && d2 <= 1.0 => {
                let ds = (1.0 - mac(sa, sb)) / self.shape_tol;
                d2 + ds * ds
            }
            _ => d2,
        }
    }
}

/// A pole in the scaled plane: `u` = ln f / ln(1 + freq_tol_rel), `v` = log10 zeta / log_damping_tol.
struct Pt {
    /// Log frequency in units of the relative frequency radius.
    u: f64,
    /// Log10 damping ratio in units of the damping radius.
    v: f64,
    /// Damping ratio, raised to `min_damping_ratio`.
    zeta: f64,
    /// Cells to search on each side in `u` (covers the widest neighbourhood of this pole).
    reach_u: i64,
    /// Grid cell of (u, v).
    cell: (i64, i64),
    /// Index of the pole in the input slice.
    idx: usize,
    /// Channel id (index among the distinct channels of the used poles).
    ch: usize,
    /// Mode shape of the pole, when the identification gave one.
    shape: Option<Vec<[f64; 2]>>,
}

/// Range of points (`start..end` into the sorted points) of each occupied grid cell.
type Cells = HashMap<(i64, i64), (usize, usize)>;

/// The points sorted by cell, with each cell's range, for neighbour queries.
struct Grid<'a> {
    pts: &'a [Pt],
    cells: Cells,
    metric: Metric,
}

impl Grid<'_> {
    /// Calls `f(j, squared_distance)` for every neighbour j (distance <= 1), i itself included.
    fn for_each_neighbour(&self, i: usize, mut f: impl FnMut(usize, f64)) {
        let pi = &self.pts[i];
        for dx in -pi.reach_u..=pi.reach_u {
            for dy in -REACH..=REACH {
                if let Some(&(a, b)) = self.cells.get(&(pi.cell.0 + dx, pi.cell.1 + dy)) {
                    for (j, pj) in self.pts[a..b].iter().enumerate() {
                        let d2 = self.metric.dist2(pi, pj);
                        if d2 <= 1.0 {
                            f(a + j, d2);
                        }
                    }
                }
            }
        }
    }

    /// Number of neighbours (i included), counting stops at `limit`.
    fn count_neighbours_upto(&self, i: usize, limit: usize) -> usize {
        let pi = &self.pts[i];
        let mut n = 0;
        for dx in -pi.reach_u..=pi.reach_u {
            for dy in -REACH..=REACH {
                if let Some(&(a, b)) = self.cells.get(&(pi.cell.0 + dx, pi.cell.1 + dy)) {
                    for pj in &self.pts[a..b] {
                        if self.metric.dist2(pi, pj) <= 1.0 {
                            n += 1;
                            if n >= limit {
                                return n;
                            }
                        }
                    }
                }
            }
        }
        n
    }
}

/// Disjoint sets over point indices (union by size, path compression).
struct UnionFind {
    parent: Vec<usize>,
    size: Vec<usize>,
}

impl UnionFind {
    fn new(n: usize) -> Self {
        UnionFind {
            parent: (0..n).collect(),
            size: vec![1; n],
        }
    }
    fn find(&mut self, mut x: usize) -> usize {
        let mut root = x;
        while self.parent[root] != root {
            root = self.parent[root];
        }
        while self.parent[x] != root {
            let next = self.parent[x];
            self.parent[x] = root;
            x = next;
        }
        root
    }
    fn union(&mut self, a: usize, b: usize) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra == rb {
            return;
        }
        let (big, small) = if self.size[ra] >= self.size[rb] {
            (ra, rb)
        } else {
            (rb, ra)
        };
        self.parent[small] = big;
        self.size[big] += self.size[small];
    }
}
