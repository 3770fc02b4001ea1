//! Fill-reducing orderings: METIS nested dissection (through `metis-sys`,
//! which vendors METIS 5 and builds it with the C compiler) or faer's AMD.
//!
//! METIS draws its random numbers from one Mersenne Twister whose state is a
//! plain static of the process (GKlib's `random.c`), reseeded at the start of
//! every `METIS_NodeND`. Two orderings computed at the same time on different
//! threads (a limit analysis's curves, the settings of an accuracy study, tests
//! run in parallel) would draw from that one state in an order set by the
//! scheduler, and so get different orderings of the same graph from run to run,
//! hence factorisations that differ by round-off (measured: reduced mass
//! matrices of the 2D blade pair 10⁻¹¹ apart, enough to move a continuation
//! path next to its folds). Every call therefore holds [`METIS_LOCK`]: the
//! ordering of a graph is the same whatever runs beside it.

use crate::csc::Csc;
use crate::ReductionError;

/// Fill-reducing ordering of the sparse Cholesky factorisations.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Ordering {
    /// METIS nested dissection (`METIS_NodeND`). On FE meshes it gives a
    /// sparser factor and a faster factorisation than AMD.
    #[default]
    Metis,
    /// faer's approximate minimum degree.
    Amd,
}

impl std::fmt::Display for Ordering {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Ordering::Metis => write!(f, "METIS"),
            Ordering::Amd => write!(f, "AMD"),
        }
    }
}

/// Held through every call into METIS (see the module docs).
static METIS_LOCK: std::sync::Mutex<()> = std::sync::Mutex::new(());

/// Nested-dissection ordering of the graph of the symmetric matrix whose lower
/// triangle is `lower`. Returns `(fwd, inv)` with `fwd[new] = old` and
/// `inv[old] = new`.
pub(crate) fn metis_nd(lower: &Csc) -> Result<(Vec<usize>, Vec<usize>), ReductionError> {
    let n = lower.ncols;
    if n == 0 {
        return Ok((Vec::new(), Vec::new()));
    }
    // adjacency of the full symmetric graph, no self loops
    let mut deg = vec![0usize; n + 1];
    for j in 0..n {
        let (rows, _) = lower.col(j);
        for &i in rows {
            if i != j {
                deg[i + 1] += 1;
                deg[j + 1] += 1;
            }
        }
    }
    for i in 0..n {
        deg[i + 1] += deg[i];
    }
    let n_adj = deg[n];
    if n_adj > i32::MAX as usize || n > i32::MAX as usize {
        return Err(ReductionError::Ordering(format!(
            "graph with {n} vertices and {n_adj} adjacency entries exceeds METIS' 32-bit indices"
        )));
    }
    let mut next: Vec<usize> = deg[..n].to_vec();
    let mut adjncy = vec![0i32; n_adj];
    for j in 0..n {
        let (rows, _) = lower.col(j);
        for &i in rows {
            if i != j {
                adjncy[next[i]] = j as i32;
                next[i] += 1;
                adjncy[next[j]] = i as i32;
                next[j] += 1;
            }
        }
    }
    drop(next);
    let mut xadj: Vec<i32> = deg.iter().map(|&d| d as i32).collect();
    drop(deg);
    let mut nvtxs = n as i32;
    let mut options = [0i32; metis_sys::METIS_NOPTIONS as usize];
    let mut perm = vec![0i32; n];
    let mut iperm = vec![0i32; n];
    // A poisoned lock only means another ordering panicked; METIS' state is
    // reseeded by the next call, so the lock is taken all the same.
    let _metis = METIS_LOCK
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    // SAFETY: arrays have the sizes METIS expects (xadj n+1, adjncy xadj[n],
    // options METIS_NOPTIONS, perm/iperm n); METIS does not keep pointers.
    let status = unsafe {
        metis_sys::METIS_SetDefaultOptions(options.as_mut_ptr());
        options[metis_sys::moptions_et_METIS_OPTION_NUMBERING as usize] = 0;
        metis_sys::METIS_NodeND(
            &mut nvtxs,
            xadj.as_mut_ptr(),
            adjncy.as_mut_ptr(),
            std::ptr::null_mut(),
            options.as_mut_ptr(),
            perm.as_mut_ptr(),
            iperm.as_mut_ptr(),
        )
    };
    if status != metis_sys::rstatus_et_METIS_OK {
        return Err(ReductionError::Ordering(format!(
            "METIS_NodeND returned status {status} on a graph with {n} vertices"
        )));
    }
    // METIS: row i of the permuted matrix is row perm[i] of the original,
    // i.e. perm[new] = old, iperm[old] = new.
    let fwd: Vec<usize> = perm.iter().map(|&p| p as usize).collect();
    let mut inv = vec![usize::MAX; n];
    for (new, &old) in fwd.iter().enumerate() {
        if old >= n || inv[old] != usize::MAX {
            return Err(ReductionError::Ordering(
                "METIS_NodeND returned an invalid permutation".into(),
            ));
        }
        inv[old] = new;
    }
    Ok((fwd, inv))
}
