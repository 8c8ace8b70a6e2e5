//! The bench's tables: one value per cell, written as Markdown (stdout), CSV and JSON.

/// One cell. Numbers keep their full value for CSV and JSON; `Num`'s second field is the
/// number of decimals shown in Markdown.
#[derive(Clone, Debug)]
pub enum Cell {
    Text(String),
    Int(u64),
    Num(f64, usize),
    /// Not measured or not applicable: `—` in Markdown, empty in CSV, null in JSON.
    None,
}

impl Cell {
    pub fn text(s: impl Into<String>) -> Cell {
        Cell::Text(s.into())
    }

    fn markdown(&self) -> String {
        match self {
            Cell::Text(s) => s.replace('|', "\\|"),
            Cell::Int(n) => super::thousands(*n),
            Cell::Num(x, d) => format!("{x:.d$}"),
            Cell::None => "—".into(),
        }
    }

    fn csv(&self) -> String {
        match self {
            Cell::Text(s) if s.contains([',', '"', '\n']) => format!("\"{}\"", s.replace('"', "\"\"")),
            Cell::Text(s) => s.clone(),
            Cell::Int(n) => n.to_string(),
            Cell::Num(x, _) => x.to_string(),
            Cell::None => String::new(),
        }
    }

    fn json(&self) -> serde_json::Value {
        match self {
            Cell::Text(s) => s.clone().into(),
            Cell::Int(n) => (*n).into(),
            Cell::Num(x, _) if x.is_finite() => (*x).into(),
            Cell::Num(..) | Cell::None => serde_json::Value::Null,
        }
    }
}

impl From<&str> for Cell {
    fn from(s: &str) -> Cell {
        Cell::Text(s.to_string())
    }
}

impl From<String> for Cell {
    fn from(s: String) -> Cell {
        Cell::Text(s)
    }
}

impl From<usize> for Cell {
    fn from(n: usize) -> Cell {
        Cell::Int(n as u64)
    }
}

impl From<u64> for Cell {
    fn from(n: u64) -> Cell {
        Cell::Int(n)
    }
}

impl<T: Into<Cell>> From<Option<T>> for Cell {
    fn from(v: Option<T>) -> Cell {
        v.map_or(Cell::None, Into::into)
    }
}

/// A number with `decimals` decimals in Markdown.
pub fn num(x: f64, decimals: usize) -> Cell {
    Cell::Num(x, decimals)
}

/// A table: `name` is its file stem (`speed_uniform` → `speed_uniform.csv`).
pub struct Table {
    pub name: String,
    pub title: String,
    pub columns: Vec<String>,
    pub rows: Vec<Vec<Cell>>,
    /// Lines printed under the table (and stored in JSON): what was measured, and how.
    pub notes: Vec<String>,
    /// Printed on stdout (long tables of raw points go to the files only).
    pub print: bool,
}

impl Table {
    pub fn new(name: &str, title: &str, columns: &[&str]) -> Table {
        Table {
            name: name.into(),
            title: title.into(),
            columns: columns.iter().map(|c| c.to_string()).collect(),
            rows: Vec::new(),
            notes: Vec::new(),
            print: true,
        }
    }

    /// Appends a row. Precondition: as many cells as columns (checked: a short row is a bug
    /// in a suite, not bad input).
    pub fn row(&mut self, cells: Vec<Cell>) {
        assert_eq!(cells.len(), self.columns.len(), "table {}: row width", self.name);
        self.rows.push(cells);
    }

    pub fn note(&mut self, text: impl Into<String>) {
        self.notes.push(text.into());
    }

    pub fn markdown(&self) -> String {
        let mut s = format!("### {}\n\n| {} |\n|", self.title, self.columns.join(" | "));
        for _ in &self.columns {
            s += " --- |";
        }
        s.push('\n');
        for r in &self.rows {
            let cells: Vec<String> = r.iter().map(Cell::markdown).collect();
            s += &format!("| {} |\n", cells.join(" | "));
        }
        for n in &self.notes {
            s += &format!("\n{n}\n");
        }
        s.push('\n');
        s
    }

    pub fn csv(&self) -> String {
        let header: Vec<String> = self.columns.iter().map(|c| Cell::text(c.clone()).csv()).collect();
        let mut s = header.join(",") + "\n";
        for r in &self.rows {
            let cells: Vec<String> = r.iter().map(Cell::csv).collect();
            s += &(cells.join(",") + "\n");
        }
        s
    }

    /// `{name, title, columns, rows: [{column: value}], notes}`.
    pub fn json(&self) -> serde_json::Value {
        let rows: Vec<serde_json::Value> = self
            .rows
            .iter()
            .map(|r| {
                let m: serde_json::Map<String, serde_json::Value> =
                    self.columns.iter().cloned().zip(r.iter().map(Cell::json)).collect();
                m.into()
            })
            .collect();
        serde_json::json!({
            "name": self.name,
            "title": self.title,
            "columns": self.columns,
            "rows": rows,
            "notes": self.notes,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_table_three_forms() {
        let mut t = Table::new("t", "T", &["model", "triangles", "ms"]);
        t.row(vec!["a, b".into(), 1234567usize.into(), num(1.23456, 2)]);
        t.row(vec!["c".into(), Cell::None, num(2.0, 1)]);
        assert_eq!(t.markdown(), "### T\n\n| model | triangles | ms |\n| --- | --- | --- |\n| a, b | 1,234,567 | 1.23 |\n| c | — | 2.0 |\n\n");
        assert_eq!(t.csv(), "model,triangles,ms\n\"a, b\",1234567,1.23456\nc,,2\n");
        let j = t.json();
        assert_eq!(j["rows"][0]["triangles"], 1234567);
        assert!(j["rows"][1]["triangles"].is_null());
        assert_eq!(j["rows"][1]["ms"], 2.0);
    }
}
