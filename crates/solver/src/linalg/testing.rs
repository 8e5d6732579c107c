//! Small test systems of the linear-algebra tests: 5-point Laplacians on grids and
//! strips, with Dirichlet, periodic or one-way (inlet-like) couplings.

use super::CsrMatrix;

/// 5-point Laplacian on an m×m grid with Dirichlet boundary, as a CsrMatrix.
pub fn grid(m: usize) -> CsrMatrix {
    strip(m, m)
}

/// 5-point Laplacian on an `rows`×`m` grid with Dirichlet boundary.
pub fn strip(rows: usize, m: usize) -> CsrMatrix {
    let mut a = CsrMatrix { row_ptr: vec![0], ..Default::default() };
    for i in 0..rows {
        for j in 0..m {
            let k = i * m + j;
            let mut push = |c: usize, v: f64| a.push(c, v);
            if i > 0 {
                push(k - m, -1.0);
            }
            if j > 0 {
                push(k - 1, -1.0);
            }
            push(k, 4.0);
            if j + 1 < m {
                push(k + 1, -1.0);
            }
            if i + 1 < rows {
                push(k + m, -1.0);
            }
            a.end_row();
        }
    }
    a
}

/// The strip with one-way links in its first row of cells, as an open channel's inlet
/// buffer makes them (a buffer particle shares the unknown of the fluid particle
/// inside it: the rows next to it gain that unknown's column, whose row does not gain
/// theirs), keeping the rows' sums.
pub fn strip_with_inlet_links(rows: usize, m: usize) -> CsrMatrix {
    let s = strip(rows, m);
    let mut a = CsrMatrix { row_ptr: vec![0], ..Default::default() };
    for k in 0..s.n() {
        for (c, v) in s.row(k) {
            a.push(c as usize, v);
        }
        if k < m {
            a.push(k + 2 * m, -0.5);
            a.push(k, 0.5);
        }
        a.end_row();
    }
    a
}
