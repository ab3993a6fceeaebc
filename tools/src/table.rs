//! Aligned markdown tables (comfy-table's markdown preset): the same text is printed on
//! stdout and written to `docs/`, readable in both.

use comfy_table::{presets::ASCII_MARKDOWN, CellAlignment, ContentArrangement, Table};

/// An empty markdown table with these column headers (no wrapping: rows stay one line).
#[must_use]
#[inline]
pub fn markdown(headers: &[&str]) -> Table {
    let mut t = Table::new();
    t.load_preset(ASCII_MARKDOWN)
        .set_content_arrangement(ContentArrangement::Disabled)
        .set_header(headers.to_vec());
    t
}

/// Right-aligns the numeric columns `cols`.
#[inline]
pub fn right_align(t: &mut Table, cols: &[usize]) {
    for &c in cols {
        if let Some(col) = t.column_mut(c) {
            col.set_cell_alignment(CellAlignment::Right);
        }
    }
}
