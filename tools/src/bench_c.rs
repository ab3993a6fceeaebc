//! The hand-written Eigen baseline, read from the markdown that `c_tests/bench_kernels --out`
//! writes (`docs/bench-c.md`; the main job runs that program before this report).
//!
//! What is read: the `CPU:` line, and from the timing table (the one whose header has the
//! columns "combined" and "Eigen") per row "3D f32", "2D f64", … the ns per particle of
//! `ampm_ahat_chat_z_batch` ("combined", on the library's default instruction set) and of the
//! Eigen baseline (one `Eigen::JacobiSVD` per particle, Â and Ĉ:Z written by hand). Both were
//! timed in that program's run on its own workload (σᵢ log-uniform in [0.5, 2], its own seed
//! and particle count).

use std::path::Path;
use std::time::SystemTime;

/// One row of the timing table.
#[derive(Clone, Debug)]
pub struct Row {
    /// 2 or 3.
    pub dim: usize,
    /// "f32" or "f64".
    pub precision: String,
    /// ns per particle of `ampm_ahat_chat_z_batch`.
    pub combined: f64,
    /// ns per particle of the Eigen baseline.
    pub eigen: f64,
}

/// What the report takes from the file.
#[derive(Clone, Debug)]
pub struct BenchC {
    /// The file read.
    pub path: String,
    /// The CPU model named on its `CPU:` line.
    pub cpu: String,
    /// Its particles per case (`N = …` on that line).
    pub n: Option<usize>,
    /// Minutes between the file's last modification and the reading (None if unknown).
    pub age_minutes: Option<f64>,
    /// The timing rows.
    pub rows: Vec<Row>,
}

impl BenchC {
    /// The row of a dimension × precision.
    #[must_use]
    pub fn row(&self, dim: usize, precision: &str) -> Option<&Row> {
        self.rows
            .iter()
            .find(|r| r.dim == dim && r.precision == precision)
    }
}

/// Cells of a markdown table line (`| a | b |` → `["a", "b"]`), `None` for other lines.
fn cells(line: &str) -> Option<Vec<&str>> {
    let l = line.trim();
    let inner = l.strip_prefix('|')?.strip_suffix('|')?;
    Some(inner.split('|').map(str::trim).collect())
}

/// Parses the text of `docs/bench-c.md`.
///
/// # Errors
/// When no table has the columns "case", "combined" and "Eigen", or a row of it does not parse.
pub fn parse(text: &str) -> Result<(String, Option<usize>, Vec<Row>), String> {
    let cpu_line = text.lines().find_map(|l| l.strip_prefix("CPU: "));
    let cpu = cpu_line
        .map(|l| l.split(';').next().unwrap_or(l).trim().to_string())
        .unwrap_or_else(|| "unknown CPU".into());
    let n = cpu_line.and_then(|l| {
        l.split(';')
            .find_map(|part| part.trim().strip_prefix("N = "))
            .and_then(|x| x.trim().parse().ok())
    });
    let mut lines = text.lines();
    let (ci, ei) = loop {
        let Some(l) = lines.next() else {
            return Err("no table with the columns \"combined\" and \"Eigen\"".into());
        };
        if let Some(h) = cells(l) {
            let col = |name: &str| h.iter().position(|c| *c == name);
            if let (Some(0), Some(c), Some(e)) = (col("case"), col("combined"), col("Eigen")) {
                break (c, e);
            }
        }
    };
    let mut rows = Vec::new();
    for l in lines {
        let Some(c) = cells(l) else { break };
        if c.first().is_some_and(|x| x.starts_with("---")) {
            continue;
        }
        let bad = || format!("unreadable row {l:?}");
        let (d, p) = c[0].split_once(' ').ok_or_else(bad)?;
        let dim = match d {
            "2D" => 2,
            "3D" => 3,
            _ => return Err(bad()),
        };
        let num = |i: usize| c.get(i).and_then(|x| x.parse::<f64>().ok()).ok_or_else(bad);
        rows.push(Row {
            dim,
            precision: p.to_string(),
            combined: num(ci)?,
            eigen: num(ei)?,
        });
    }
    if rows.is_empty() {
        return Err("the timing table has no rows".into());
    }
    Ok((cpu, n, rows))
}

/// Reads `path`: `Ok(None)` when it does not exist.
///
/// # Errors
/// When it exists but cannot be read or parsed.
pub fn read(path: &Path) -> Result<Option<BenchC>, String> {
    let text = match std::fs::read_to_string(path) {
        Ok(t) => t,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(format!("reading {}: {e}", path.display())),
    };
    let (cpu, n, rows) = parse(&text).map_err(|e| format!("{}: {e}", path.display()))?;
    let age_minutes = std::fs::metadata(path)
        .and_then(|m| m.modified())
        .ok()
        .and_then(|t| SystemTime::now().duration_since(t).ok())
        .map(|d| d.as_secs_f64() / 60.0);
    // Shown relative to the workspace when inside it ("docs/bench-c.md").
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let shown = match (path.canonicalize(), root.canonicalize()) {
        (Ok(p), Ok(r)) => p.strip_prefix(&r).map_or(p.clone(), Path::to_path_buf),
        _ => path.to_path_buf(),
    };
    Ok(Some(BenchC {
        path: shown.display().to_string(),
        cpu,
        n,
        age_minutes,
        rows,
    }))
}

#[cfg(test)]
mod tests {
    use super::parse;

    #[test]
    fn parses_the_timing_table() {
        let text = "# t\n\nCPU: Some CPU; ISA x; N = 4096; compiler: g++\n\n\
            | case | separate calls | combined | Eigen | Eigen/combined |\n\
            |---|---:|---:|---:|---:|\n\
            | 3D f32 | 117 | 73.1 | 1344 | 18.40 |\n\
            | 2D f64 | 115 | 37.2 | 323 | 8.68 |\n\
            \n| case | result |\n|---|---|\n| 3D f32 | x |\n";
        let (cpu, n, rows) = parse(text).unwrap();
        assert_eq!(cpu, "Some CPU");
        assert_eq!(n, Some(4096));
        assert_eq!(rows.len(), 2);
        assert_eq!((rows[0].dim, rows[0].precision.as_str()), (3, "f32"));
        assert_eq!((rows[0].combined, rows[0].eigen), (73.1, 1344.0));
        assert_eq!(
            (rows[1].dim, rows[1].combined, rows[1].eigen),
            (2, 37.2, 323.0)
        );
    }

    #[test]
    fn refuses_a_file_without_the_table() {
        assert!(parse("| case | result |\n|---|---|\n").is_err());
    }
}
