//! The start of a table: its header (or that it has none), an XYZ file's atom count and
//! comment line, the column roles and the colour scale.

use csv::ByteRecord;

use crate::particles::columns::{listed, MAX_COLUMNS};

use super::*;

impl ParticleReader {
    /// Reads the header (or decides there is none), the column roles and the colour scale.
    pub(super) fn start(&mut self) -> Result<(), Diagnostic> {
        let mut first = ByteRecord::new();
        let Some(mut line) = self.read_row(&mut first)? else {
            return Err(self.error(1, 1, "the table is empty: no header and no rows".into()));
        };
        let comma = self.delimiter == Delimiter::Semicolon;
        // XYZ: a line with only the atom count, then a comment line.
        if self.delimiter == Delimiter::Whitespace && first.len() == 1 {
            if let Ok(count) = text(&first[0]).parse::<u64>() {
                self.remaining = Some(count);
                let mut comment = ByteRecord::new();
                // The comment line may be empty, which the white-space reader skips; read it raw.
                let skipped = self.rows.skip_line();
                skipped.map_err(|m| self.read_failed(m))?;
                self.notes.push(format!(
                    "XYZ file: {count} atoms in the first frame (later frames are not read)"
                ));
                line = match self.read_row(&mut comment)? {
                    Some(l) => l,
                    None if count == 0 => {
                        return Err(self.error(1, 1, "the XYZ file holds no atoms".into()))
                    }
                    None => {
                        return Err(self.error(
                            2,
                            1,
                            format!("the XYZ header says {count} atoms, but no atom lines follow"),
                        ))
                    }
                };
                first = comment;
                if self.opts.columns.positional.is_none() {
                    self.opts.columns.positional =
                        Some(["element", "x", "y", "z"].map(String::from).to_vec());
                }
            }
        }
        if first.len() > MAX_COLUMNS {
            return Err(self.error(
                line,
                1,
                format!(
                    "the first row has {} columns: a particle table has at most {MAX_COLUMNS}",
                    first.len()
                ),
            ));
        }
        let xyz = self.remaining.is_some();
        let non_number = |f: &[u8]| number(f, comma).is_none();
        let (names, is_header) = match self.opts.columns.positional.clone() {
            Some(names) => {
                // A header is a first row with text where the named columns want numbers.
                let map = ColumnMap::from_names(&names).map_err(|m| self.error(line, 1, m))?;
                let is_header = !xyz
                    && Role::ALL
                        .iter()
                        .filter(|r| **r != Role::Element)
                        .filter_map(|r| map.get(*r))
                        .any(|c| first.get(c).is_some_and(non_number));
                (names, is_header)
            }
            None if first.iter().any(non_number) => {
                (first.iter().map(|f| text(f).to_string()).collect(), true)
            }
            None => match first.len() {
                3 => (["x", "y", "z"].map(String::from).to_vec(), false),
                4 => (["x", "y", "z", "radius"].map(String::from).to_vec(), false),
                n => {
                    return Err(self.error(
                        line,
                        1,
                        format!(
                            "the first row is numbers, not a header, and {n} columns are too many to guess; name them in order with --columns, e.g. --columns x,y,z,radius,red,green,blue"
                        ),
                    ))
                }
            },
        };
        if !is_header && self.opts.columns.positional.is_none() {
            self.notes
                .push(format!("no header: columns taken as {}", listed(&names)));
        }
        let mut map = ColumnMap::from_names(&names).map_err(|m| self.error(line, 1, m))?;
        map.apply_overrides(&self.opts.columns.overrides)
            .map_err(|m| self.error(line, 1, m))?;
        map.check(self.opts.radius.is_some())
            .map_err(|m| self.error(line, 1, m))?;
        if self.opts.radius.is_some()
            && (map.get(Role::Radius).is_some() || map.get(Role::Diameter).is_some())
        {
            self.notes
                .push("--radius given: the radius column is not used".to_string());
        }
        if map.get(Role::Element).is_some() {
            let radius = self.opts.radius.is_none()
                && map.get(Role::Radius).is_none()
                && map.get(Role::Diameter).is_none();
            let colour = map.get(Role::Red).is_none();
            self.element_gives = (radius, colour);
            if radius || colour {
                let what = match (radius, colour) {
                    (true, true) => "radii (van der Waals, in angstrom) and colours (CPK)",
                    (true, false) => "radii (van der Waals, in angstrom)",
                    _ => "colours (CPK)",
                };
                self.notes.push(format!("{what} from the element column"));
            }
        }
        if !map.ignored.is_empty() {
            self.notes
                .push(format!("columns not used: {}", listed(&map.ignored)));
        }
        self.map = map;
        if !is_header {
            self.held.push_back(Held { line, rec: first });
        }
        // Hold the first rows back to decide the colour scale.
        let colour_cols: Vec<usize> = Role::ALL
            .iter()
            .filter(|r| r.is_colour())
            .filter_map(|r| self.map.get(*r))
            .collect();
        self.scale = match self.opts.color_scale {
            Some(s) => s,
            None if colour_cols.is_empty() => ColorScale::Unit,
            None => {
                while self.held.len() < SNIFF_ROWS && self.remaining_after_held() {
                    let mut rec = ByteRecord::new();
                    match self.read_row(&mut rec)? {
                        Some(line) => self.held.push_back(Held { line, rec }),
                        None => break,
                    }
                }
                let mut fractional = false;
                let mut above_one = false;
                for h in &self.held {
                    for &c in &colour_cols {
                        if let Some(f) = h.rec.get(c) {
                            let t = text(f);
                            if t.contains(['.', 'e', 'E']) || (comma && t.contains(',')) {
                                fractional = true;
                            } else if number(f, comma).is_some_and(|v| v > 1.0) {
                                above_one = true;
                            }
                        }
                    }
                }
                let scale = if above_one && !fractional {
                    ColorScale::Byte
                } else {
                    ColorScale::Unit
                };
                self.notes.push(format!(
                    "colours read as {} (from the first {} rows; --color-scale overrides)",
                    match scale {
                        ColorScale::Unit => "0-1 floats",
                        ColorScale::Byte => "0-255 integers",
                    },
                    self.held.len()
                ));
                scale
            }
        };
        Ok(())
    }
}
