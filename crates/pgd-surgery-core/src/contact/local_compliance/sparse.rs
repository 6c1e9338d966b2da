//! The two sparse containers the near-field compliance is kept and applied in.

/// Compressed rows: row `i`'s entries are `columns[offsets[i]..offsets[i + 1]]` with their
/// `values`, columns ascending.
#[derive(Clone, Debug, Default)]
pub(super) struct SparseRows {
    offsets: Vec<u32>,
    columns: Vec<u32>,
    values: Vec<f64>,
}

impl SparseRows {
    /// From each row's entries, columns ascending within each.
    pub(super) fn from_rows(rows: impl IntoIterator<Item = Vec<(u32, f64)>>) -> Self {
        let mut sparse = Self::default();
        sparse.clear();
        for row in rows {
            sparse.push_row(row);
        }
        sparse
    }

    /// Room for `rows` rows holding `entries` entries in all, so that filling it up to that
    /// allocates nothing.
    pub(super) fn reserve(&mut self, rows: usize, entries: usize) {
        self.offsets.reserve(rows + 1);
        self.columns.reserve(entries);
        self.values.reserve(entries);
    }

    /// Entries in all rows.
    pub(super) fn entries(&self) -> usize {
        self.columns.len()
    }

    /// Drops every row, keeping the storage.
    pub(super) fn clear(&mut self) {
        self.offsets.clear();
        self.offsets.push(0);
        self.columns.clear();
        self.values.clear();
    }

    /// Appends a row, its entries' columns ascending.
    pub(super) fn push_row(&mut self, entries: impl IntoIterator<Item = (u32, f64)>) {
        let start = self.columns.len();
        for (column, value) in entries {
            self.columns.push(column);
            self.values.push(value);
        }
        debug_assert!(
            self.columns[start..].windows(2).all(|w| w[0] < w[1]),
            "unsorted row"
        );
        self.offsets.push(self.columns.len() as u32);
    }

    pub(super) fn rows(&self) -> usize {
        self.offsets.len() - 1
    }

    /// Row `i`'s columns and values.
    pub(super) fn row(&self, i: usize) -> (&[u32], &[f64]) {
        let range = self.offsets[i] as usize..self.offsets[i + 1] as usize;
        (&self.columns[range.clone()], &self.values[range])
    }

    /// Entry `(i, j)`, 0 where the row holds none.
    pub(super) fn get(&self, i: usize, j: usize) -> f64 {
        let (columns, values) = self.row(i);
        columns
            .binary_search(&(j as u32))
            .map_or(0.0, |k| values[k])
    }
}

/// A vector mostly zero, with the list of the entries touched since it was last cleared, so
/// that clearing it costs what was touched rather than its length.
#[derive(Clone, Debug, Default)]
pub(super) struct Scattered {
    values: Vec<f64>,
    marked: Vec<bool>,
    touched: Vec<u32>,
}

impl Scattered {
    /// Room for every entry in its list of touched ones, so that adding allocates nothing.
    pub(super) fn new(len: usize) -> Self {
        Self {
            values: vec![0.0; len],
            marked: vec![false; len],
            touched: Vec::with_capacity(len),
        }
    }

    /// The room [`Self::new`] made, again (a clone keeps only the contents).
    pub(super) fn reserve(&mut self) {
        self.touched.reserve(self.values.len() - self.touched.len());
    }

    pub(super) fn add(&mut self, i: usize, value: f64) {
        if !self.marked[i] {
            self.marked[i] = true;
            self.touched.push(i as u32);
        }
        self.values[i] += value;
    }

    pub(super) fn get(&self, i: usize) -> f64 {
        self.values[i]
    }

    /// The entries added to since the last clear, each once.
    pub(super) fn touched(&self) -> &[u32] {
        &self.touched
    }

    pub(super) fn clear(&mut self) {
        for &i in &self.touched {
            self.values[i as usize] = 0.0;
            self.marked[i as usize] = false;
        }
        self.touched.clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_pushed_read_back_and_clear() {
        let mut rows = SparseRows::from_rows([vec![(0, 1.0), (2, 2.0)], vec![]]);
        rows.push_row([(1, 3.0)]);
        assert_eq!(rows.rows(), 3);
        assert_eq!(rows.row(0), (&[0u32, 2][..], &[1.0, 2.0][..]));
        assert_eq!(
            (rows.get(0, 2), rows.get(0, 1), rows.get(2, 1)),
            (2.0, 0.0, 3.0)
        );
        assert!(rows.row(1).0.is_empty());
        rows.clear();
        assert_eq!(rows.rows(), 0);
        rows.push_row([(4, 5.0)]);
        assert_eq!((rows.rows(), rows.get(0, 4)), (1, 5.0));
    }

    #[test]
    fn a_scattered_vector_clears_what_was_touched_and_lists_each_once() {
        let mut v = Scattered::new(4);
        v.add(2, 1.0);
        v.add(0, 0.5);
        v.add(2, -1.0);
        assert_eq!(v.touched(), &[2, 0]);
        assert_eq!(v.get(2), 0.0);
        v.clear();
        assert!(v.touched().is_empty());
        assert_eq!(v.get(0), 0.0);
        v.add(0, 1.0);
        assert_eq!((v.get(0), v.touched()), (1.0, &[0u32][..]));
    }
}
