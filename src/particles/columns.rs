//! Which column holds what: header names matched to particle roles, and `--columns`.
//!
//! Names are matched after normalising: lower case, a unit in brackets or parentheses dropped
//! (`x [nm]`), and spaces, `_`, `-`, `.` and `:` removed (`Pos.X` and `pos_x` are `posx`).
//! `r` is ambiguous (radius, or red beside `g` and `b`): it means red when the header also has
//! green and blue columns, radius otherwise.

use std::fmt;

/// What a column means for a particle.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Role {
    /// The centre's x.
    X,
    /// The centre's y.
    Y,
    /// The centre's z.
    Z,
    /// The sphere's radius.
    Radius,
    /// A diameter; the radius is half of it.
    Diameter,
    /// The diffuse colour's red channel (0-1 or 0-255, see [`ColorScale`](super::ColorScale)).
    Red,
    /// The diffuse colour's green channel.
    Green,
    /// The diffuse colour's blue channel.
    Blue,
    /// Extinction coefficient sigma (per world unit) of a gas sphere.
    Density,
    /// 1 - transparency.
    Opacity,
    /// VRML Material.transparency.
    Transparency,
    /// Grey emission: the same value in all three channels.
    Emission,
    /// The emissive colour's red channel.
    EmissionRed,
    /// The emissive colour's green channel.
    EmissionGreen,
    /// The emissive colour's blue channel.
    EmissionBlue,
    /// A chemical element symbol: van der Waals radius and CPK colour when the table gives
    /// none.
    Element,
    /// A gas sphere's density profile by name (docs/model.md section 6): written as a
    /// `GasParticle`.
    Profile,
    /// The gaussian profile's width, in units of the radius.
    Width,
}

impl Role {
    /// Every role, in declaration order.
    pub const ALL: [Role; 18] = [
        Role::X,
        Role::Y,
        Role::Z,
        Role::Radius,
        Role::Diameter,
        Role::Red,
        Role::Green,
        Role::Blue,
        Role::Density,
        Role::Opacity,
        Role::Transparency,
        Role::Emission,
        Role::EmissionRed,
        Role::EmissionGreen,
        Role::EmissionBlue,
        Role::Element,
        Role::Profile,
        Role::Width,
    ];

    /// The role's canonical name, as `--columns` accepts it.
    pub fn name(self) -> &'static str {
        match self {
            Role::X => "x",
            Role::Y => "y",
            Role::Z => "z",
            Role::Radius => "radius",
            Role::Diameter => "diameter",
            Role::Red => "red",
            Role::Green => "green",
            Role::Blue => "blue",
            Role::Density => "density",
            Role::Opacity => "opacity",
            Role::Transparency => "transparency",
            Role::Emission => "emission",
            Role::EmissionRed => "emission_red",
            Role::EmissionGreen => "emission_green",
            Role::EmissionBlue => "emission_blue",
            Role::Element => "element",
            Role::Profile => "profile",
            Role::Width => "width",
        }
    }

    /// The role's place in [`Role::ALL`] (the declaration order).
    pub(crate) fn index(self) -> usize {
        self as usize
    }

    /// Whether values of this role are colours (0-1 or 0-255).
    pub fn is_colour(self) -> bool {
        matches!(
            self,
            Role::Red
                | Role::Green
                | Role::Blue
                | Role::Emission
                | Role::EmissionRed
                | Role::EmissionGreen
                | Role::EmissionBlue
        )
    }
}

impl fmt::Display for Role {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// `name` lower-cased, without a bracketed unit and without separators.
/// `names` for a message: the first 16, and how many more.
pub fn listed(names: &[String]) -> String {
    const SHOWN: usize = 16;
    let mut s = names[..names.len().min(SHOWN)].join(", ");
    if names.len() > SHOWN {
        s += &format!(", and {} more", names.len() - SHOWN);
    }
    s
}

/// The most columns a particle table may have: far more than any particle attributes, and
/// what keeps a header line of megabytes from costing memory and a message of that size.
pub const MAX_COLUMNS: usize = 4096;

/// A column name as it is matched: cut at its first `[` or `(` (a unit), without spaces,
/// tabs, `_`, `-`, `.` and `:`, in lower case.
pub fn normalise(name: &str) -> String {
    let cut = name.find(['[', '(']).unwrap_or(name.len());
    name[..cut]
        .chars()
        .filter(|c| !matches!(c, ' ' | '_' | '-' | '.' | ':' | '\t'))
        .flat_map(char::to_lowercase)
        .collect()
}

/// The role of a normalised name, `r` aside (see [`ColumnMap::from_names`]).
fn role_of(norm: &str) -> Option<Role> {
    let strip = |prefixes: &[&str]| {
        prefixes
            .iter()
            .find_map(|p| norm.strip_prefix(p))
            .unwrap_or(norm)
    };
    let axis = strip(&["position", "coord", "pos"]);
    let colour = strip(&["colour", "color", "col"]);
    let emission = strip(&["emission", "emissive"]);
    Some(match norm {
        "x" | "px" => Role::X,
        "y" | "py" => Role::Y,
        "z" | "pz" => Role::Z,
        "radius" | "rad" => Role::Radius,
        "diameter" | "diam" => Role::Diameter,
        "red" | "cr" => Role::Red,
        "green" | "g" | "cg" => Role::Green,
        "blue" | "b" | "cb" => Role::Blue,
        "density" | "sigma" | "extinction" => Role::Density,
        "opacity" | "alpha" => Role::Opacity,
        "transparency" => Role::Transparency,
        "emission" | "emissive" | "glow" => Role::Emission,
        "element" | "elem" | "symbol" => Role::Element,
        "profile" | "densityprofile" => Role::Profile,
        "width" | "profilewidth" => Role::Width,
        _ if axis != norm && ["x", "y", "z"].contains(&axis) => match axis {
            "x" => Role::X,
            "y" => Role::Y,
            _ => Role::Z,
        },
        _ if emission != norm => match emission {
            "r" | "red" => Role::EmissionRed,
            "g" | "green" => Role::EmissionGreen,
            "b" | "blue" => Role::EmissionBlue,
            _ => return None,
        },
        _ if colour != norm => match colour {
            "r" | "red" => Role::Red,
            "g" | "green" => Role::Green,
            "b" | "blue" => Role::Blue,
            _ => return None,
        },
        _ => return None,
    })
}

/// The role a `--columns` entry names (canonical names and every header alias).
fn role_named(name: &str) -> Option<Role> {
    let norm = normalise(name);
    if norm == "r" {
        // Spelled out in --columns, `r` is the radius; red is `red`.
        return Some(Role::Radius);
    }
    role_of(&norm)
}

/// For each role, the 0-based column that holds it.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ColumnMap {
    cols: [Option<usize>; 18],
    /// Column names (from the header or `--columns`), for messages.
    pub names: Vec<String>,
    /// Columns that mean nothing to us, listed once for the user.
    pub ignored: Vec<String>,
}

impl ColumnMap {
    /// The 0-based column that holds `role`, if any.
    pub fn get(&self, role: Role) -> Option<usize> {
        self.cols[role.index()]
    }

    fn set(&mut self, role: Role, col: usize) -> Result<(), String> {
        if let Some(old) = self.cols[role.index()] {
            if old != col {
                return Err(format!(
                    "columns {} (\"{}\") and {} (\"{}\") both mean {role}; say which with --columns {role}=NAME",
                    old + 1,
                    self.name(old),
                    col + 1,
                    self.name(col)
                ));
            }
        }
        self.cols[role.index()] = Some(col);
        Ok(())
    }

    /// The name of column `col` (0-based) for messages.
    pub fn name(&self, col: usize) -> String {
        self.names
            .get(col)
            .cloned()
            .unwrap_or_else(|| format!("column {}", col + 1))
    }

    /// Roles from column names (a header, or a positional `--columns` list).
    pub fn from_names(names: &[String]) -> Result<ColumnMap, String> {
        let norms: Vec<String> = names.iter().map(|n| normalise(n)).collect();
        let has = |role: Role| norms.iter().any(|n| role_of(n) == Some(role));
        let r_is_red = has(Role::Green) && has(Role::Blue);
        let mut map = ColumnMap {
            names: names.to_vec(),
            ..ColumnMap::default()
        };
        for (col, norm) in norms.iter().enumerate() {
            let role = match norm.as_str() {
                "r" if r_is_red => Some(Role::Red),
                "r" => Some(Role::Radius),
                "" | "skip" | "ignore" => None,
                n => role_of(n),
            };
            match role {
                Some(role) => map.set(role, col)?,
                None if norm.is_empty() || norm == "skip" || norm == "ignore" => {}
                None => map.ignored.push(names[col].clone()),
            }
        }
        Ok(map)
    }

    /// Applies `ROLE=NAME` / `ROLE=NUMBER` overrides (NUMBER is 1-based).
    pub fn apply_overrides(&mut self, overrides: &[(Role, String)]) -> Result<(), String> {
        for (role, target) in overrides {
            let col = match target.parse::<usize>() {
                Ok(0) => return Err(format!("--columns {role}=0: columns count from 1")),
                Ok(n) => n - 1,
                Err(_) => {
                    let want = normalise(target);
                    self.names
                        .iter()
                        .position(|n| normalise(n) == want)
                        .ok_or_else(|| {
                            format!(
                                "--columns {role}={target}: no column named \"{target}\"; the columns are: {}",
                                listed(&self.names)
                            )
                        })?
                }
            };
            // The column now means `role` only.
            for c in self.cols.iter_mut() {
                if *c == Some(col) {
                    *c = None;
                }
            }
            self.cols[role.index()] = Some(col);
            let name = self.name(col);
            self.ignored.retain(|n| *n != name);
        }
        Ok(())
    }

    /// Checks that the roles make a particle; `radius_given` is `--radius`.
    pub fn check(&self, radius_given: bool) -> Result<(), String> {
        let missing: Vec<&str> = [Role::X, Role::Y, Role::Z]
            .iter()
            .filter(|r| self.get(**r).is_none())
            .map(|r| r.name())
            .collect();
        if !missing.is_empty() {
            return Err(format!(
                "no column for {} (columns: {}); name them with --columns, e.g. --columns x=COL",
                missing.join(", "),
                listed(&self.names)
            ));
        }
        if !radius_given
            && self.get(Role::Radius).is_none()
            && self.get(Role::Diameter).is_none()
            && self.get(Role::Element).is_none()
        {
            return Err(format!(
                "no radius column (columns: {}); give every particle a radius with --radius R, or name the column with --columns radius=COL",
                listed(&self.names)
            ));
        }
        let rgb = [Role::Red, Role::Green, Role::Blue].map(|r| self.get(r).is_some());
        if rgb.iter().any(|&b| b) && !rgb.iter().all(|&b| b) {
            return Err("a colour needs all three of red, green and blue columns".to_string());
        }
        let erg = [Role::EmissionRed, Role::EmissionGreen, Role::EmissionBlue]
            .map(|r| self.get(r).is_some());
        if erg.iter().any(|&b| b) && !erg.iter().all(|&b| b) {
            return Err(
                "an emission colour needs all three of emission_red, emission_green and emission_blue columns"
                    .to_string(),
            );
        }
        if erg[0] && self.get(Role::Emission).is_some() {
            return Err(
                "both a grey emission column and emission colour columns; keep one".to_string(),
            );
        }
        let gas: Vec<&str> = [Role::Density, Role::Opacity, Role::Transparency]
            .iter()
            .filter(|r| self.get(**r).is_some())
            .map(|r| r.name())
            .collect();
        if gas.len() > 1 {
            return Err(format!(
                "columns for {} all set how see-through a particle is; keep one",
                gas.join(" and ")
            ));
        }
        Ok(())
    }
}

/// What `--columns` said.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ColumnSpec {
    /// `ROLE=NAME` or `ROLE=NUMBER` entries.
    pub overrides: Vec<(Role, String)>,
    /// A plain list: the names of the columns in order (for files without a header).
    pub positional: Option<Vec<String>>,
}

impl ColumnSpec {
    /// Parses `--columns` values: either all `ROLE=NAME` entries or one positional list,
    /// comma separated (several `--columns` options add up).
    pub fn parse(values: &[String]) -> Result<ColumnSpec, String> {
        let mut spec = ColumnSpec::default();
        let mut positional = Vec::new();
        for entry in values.iter().flat_map(|v| v.split(',')) {
            let entry = entry.trim();
            match entry.split_once('=') {
                Some((role, target)) => {
                    let r = role_named(role).ok_or_else(|| {
                        format!(
                            "--columns {entry}: unknown role \"{role}\"; roles are {}",
                            Role::ALL.map(Role::name).join(", ")
                        )
                    })?;
                    if target.trim().is_empty() {
                        return Err(format!("--columns {entry}: no column after '='"));
                    }
                    spec.overrides.push((r, target.trim().to_string()));
                }
                None => positional.push(entry.to_string()),
            }
        }
        if !positional.is_empty() {
            if !spec.overrides.is_empty() {
                return Err(
                    "--columns takes either a list of column names in order (x,y,z,radius) or ROLE=COLUMN entries, not both"
                        .to_string(),
                );
            }
            spec.positional = Some(positional);
        }
        Ok(spec)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(v: &[&str]) -> Vec<String> {
        v.iter().map(|s| s.to_string()).collect()
    }

    #[test]
    fn index_is_place_in_all() {
        for (k, r) in Role::ALL.iter().enumerate() {
            assert_eq!(r.index(), k);
        }
    }

    #[test]
    fn header_aliases() {
        let m = ColumnMap::from_names(&names(&["id", "Pos.X", "pos_y", "z [nm]", "r", "g", "b"]))
            .unwrap();
        assert_eq!(m.get(Role::X), Some(1));
        assert_eq!(m.get(Role::Y), Some(2));
        assert_eq!(m.get(Role::Z), Some(3));
        assert_eq!(m.get(Role::Red), Some(4));
        assert_eq!(m.get(Role::Radius), None);
        assert_eq!(m.ignored, vec!["id".to_string()]);
        let m = ColumnMap::from_names(&names(&["x", "y", "z", "r"])).unwrap();
        assert_eq!(m.get(Role::Radius), Some(3));
        let m = ColumnMap::from_names(&names(&[
            "x",
            "y",
            "z",
            "emission_r",
            "EmissiveGreen",
            "emission-b",
            "color_red",
        ]))
        .unwrap();
        assert_eq!(m.get(Role::EmissionRed), Some(3));
        assert_eq!(m.get(Role::EmissionGreen), Some(4));
        assert_eq!(m.get(Role::EmissionBlue), Some(5));
        assert_eq!(m.get(Role::Red), Some(6));
    }

    #[test]
    fn duplicates_and_overrides() {
        let e = ColumnMap::from_names(&names(&["x", "px", "y", "z"])).unwrap_err();
        assert!(
            e.contains("columns 1 (\"x\") and 2 (\"px\") both mean x"),
            "{e}"
        );
        let mut m = ColumnMap::from_names(&names(&["a", "b", "c", "size"])).unwrap();
        m.apply_overrides(&[
            (Role::X, "a".into()),
            (Role::Y, "2".into()),
            (Role::Z, "C".into()),
            (Role::Radius, "size".into()),
        ])
        .unwrap();
        assert_eq!(m.get(Role::Y), Some(1));
        assert_eq!(m.get(Role::Blue), None, "b now means y only");
        assert!(m.ignored.is_empty());
        assert!(m.check(false).is_ok());
        assert!(m.apply_overrides(&[(Role::X, "nope".into())]).is_err());
    }

    #[test]
    fn column_spec_forms() {
        let s = ColumnSpec::parse(&names(&["element,x,y,z"])).unwrap();
        assert_eq!(s.positional.unwrap().len(), 4);
        let s = ColumnSpec::parse(&names(&["x=a", "r=5"])).unwrap();
        assert_eq!(s.overrides[1], (Role::Radius, "5".to_string()));
        assert!(ColumnSpec::parse(&names(&["x=a,y"])).is_err());
        assert!(ColumnSpec::parse(&names(&["speed=a"])).is_err());
    }
}
