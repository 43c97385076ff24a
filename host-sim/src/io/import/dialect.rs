//! How a logger wrote its CSV: the delimiter (comma, semicolon or tab, from the first
//! line) and the decimal mark (a decimal comma is only possible when the delimiter is
//! not a comma; it is detected from the first data row). Cells may be quoted with `"`
//! (a doubled `""` inside is a quote).

use std::fmt;

/// Delimiter and decimal mark of one file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Dialect {
    pub delimiter: char,
    pub decimal_comma: bool,
}

impl fmt::Display for Dialect {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let d = match self.delimiter {
            '\t' => "tab",
            ';' => "semicolon",
            _ => "comma",
        };
        let m = if self.decimal_comma {
            "decimal comma"
        } else {
            "decimal point"
        };
        write!(f, "{d}-delimited, {m}")
    }
}

/// The delimiter of a file whose first line is `line`: tab if it has one, else
/// semicolon if it has one, else comma (counted outside quotes).
pub fn detect_delimiter(line: &str) -> char {
    let mut quoted = false;
    let (mut tabs, mut semis) = (0, 0);
    for c in line.chars() {
        match c {
            '"' => quoted = !quoted,
            '\t' if !quoted => tabs += 1,
            ';' if !quoted => semis += 1,
            _ => {}
        }
    }
    if tabs > 0 {
        '\t'
    } else if semis > 0 {
        ';'
    } else {
        ','
    }
}

/// Whether a data row written with `delimiter` uses decimal commas: some cell is a
/// number with a comma as its decimal mark (`-0,0123`, `1,5E-3`).
pub fn detect_decimal_comma(cells: &[String], delimiter: char) -> bool {
    delimiter != ','
        && cells
            .iter()
            .any(|c| parse_number(c, true).is_some() && c.contains(','))
}

/// Splits one line into trimmed cells, removing the quotes of quoted cells.
pub fn split_cells(line: &str, delimiter: char, out: &mut Vec<String>) {
    out.clear();
    let mut cell = String::new();
    let mut quoted = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '"' if quoted && chars.peek() == Some(&'"') => {
                cell.push('"');
                chars.next();
            }
            '"' => quoted = !quoted,
            c if c == delimiter && !quoted => out.push(std::mem::take(&mut cell).trim().to_owned()),
            c => cell.push(c),
        }
    }
    out.push(cell.trim().to_owned());
}

/// A cell as a number, with the file's decimal mark; a cell mixing both marks, or a
/// point in a decimal-comma file, is not a number (it may be a thousands separator).
pub fn parse_number(cell: &str, decimal_comma: bool) -> Option<f64> {
    let t = cell.trim();
    let normal = if decimal_comma {
        if t.contains('.') {
            return None;
        }
        t.replacen(',', ".", 1)
    } else {
        t.to_owned()
    };
    if normal.contains(',') {
        return None;
    }
    normal.parse::<f64>().ok()
}

impl Dialect {
    /// A cell as a number in this dialect.
    pub fn number(&self, cell: &str) -> Option<f64> {
        parse_number(cell, self.decimal_comma)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cells(line: &str, d: char) -> Vec<String> {
        let mut v = Vec::new();
        split_cells(line, d, &mut v);
        v
    }

    #[test]
    fn delimiters_and_decimal_marks_are_detected() {
        assert_eq!(detect_delimiter("time;rate;temp"), ';');
        assert_eq!(detect_delimiter("time\trate;x"), '\t');
        assert_eq!(detect_delimiter("\"a;b\",c"), ',');
        assert!(detect_decimal_comma(&cells("1;0,25;20", ';'), ';'));
        assert!(!detect_decimal_comma(&cells("1;0.25;20", ';'), ';'));
        assert!(!detect_decimal_comma(&cells("1,25,20", ','), ','));
    }

    #[test]
    fn quoted_cells_and_numbers() {
        assert_eq!(cells(" \"a;\"\"b\"\" \" ; 2 ", ';'), vec!["a;\"b\"", "2"]);
        assert_eq!(parse_number("-1,5E-3", true), Some(-1.5e-3));
        assert_eq!(parse_number("1.234,5", true), None);
        assert_eq!(parse_number("12.5", true), None);
        assert_eq!(parse_number("12,5", false), None);
        assert_eq!(parse_number("12.5", false), Some(12.5));
    }
}
