//! Radii and colours of chemical elements, for tables with an element column (XYZ files):
//! van der Waals radii in angstrom from Bondi (J. Phys. Chem. 68, 441, 1964), completed for
//! main-group elements by Mantina et al. (J. Phys. Chem. A 113, 5806, 2009), and the CPK
//! colours Jmol uses. Elements in neither list (most transition metals) have no radius here:
//! give one with `--radius`.

/// `(symbol, van der Waals radius in angstrom, colour as 0-255 RGB)`.
const ELEMENTS: &[(&str, f64, [u8; 3])] = &[
    ("H", 1.20, [255, 255, 255]),
    ("He", 1.40, [217, 255, 255]),
    ("Li", 1.82, [204, 128, 255]),
    ("Be", 1.53, [194, 255, 0]),
    ("B", 1.92, [255, 181, 181]),
    ("C", 1.70, [144, 144, 144]),
    ("N", 1.55, [48, 80, 248]),
    ("O", 1.52, [255, 13, 13]),
    ("F", 1.47, [144, 224, 80]),
    ("Ne", 1.54, [179, 227, 245]),
    ("Na", 2.27, [171, 92, 242]),
    ("Mg", 1.73, [138, 255, 0]),
    ("Al", 1.84, [191, 166, 166]),
    ("Si", 2.10, [240, 200, 160]),
    ("P", 1.80, [255, 128, 0]),
    ("S", 1.80, [255, 255, 48]),
    ("Cl", 1.75, [31, 240, 31]),
    ("Ar", 1.88, [128, 209, 227]),
    ("K", 2.75, [143, 64, 212]),
    ("Ca", 2.31, [61, 255, 0]),
    ("Ni", 1.63, [80, 208, 80]),
    ("Cu", 1.40, [200, 128, 51]),
    ("Zn", 1.39, [125, 128, 176]),
    ("Ga", 1.87, [194, 143, 143]),
    ("Ge", 2.11, [102, 143, 143]),
    ("As", 1.85, [189, 128, 227]),
    ("Se", 1.90, [255, 161, 0]),
    ("Br", 1.85, [166, 41, 41]),
    ("Kr", 2.02, [92, 184, 209]),
    ("Rb", 3.03, [112, 46, 176]),
    ("Sr", 2.49, [0, 255, 0]),
    ("Pd", 1.63, [0, 105, 133]),
    ("Ag", 1.72, [192, 192, 192]),
    ("Cd", 1.58, [255, 217, 143]),
    ("In", 1.93, [166, 117, 115]),
    ("Sn", 2.17, [102, 128, 128]),
    ("Sb", 2.06, [158, 99, 181]),
    ("Te", 2.06, [212, 122, 0]),
    ("I", 1.98, [148, 0, 148]),
    ("Xe", 2.16, [66, 158, 176]),
    ("Cs", 3.43, [87, 23, 143]),
    ("Ba", 2.68, [0, 201, 0]),
    ("Pt", 1.72, [208, 208, 224]),
    ("Au", 1.66, [255, 209, 35]),
    ("Hg", 1.55, [184, 184, 208]),
    ("Tl", 1.96, [166, 84, 77]),
    ("Pb", 2.02, [87, 89, 97]),
    ("Bi", 2.07, [158, 79, 181]),
    ("U", 1.86, [0, 143, 255]),
];

/// An element's van der Waals radius (angstrom) and colour (0-1), by symbol. Letters only
/// count, in any case, so that atom labels such as `C12` or `CL` find their element.
pub fn lookup(label: &str) -> Option<(f64, [f64; 3])> {
    let letters: String = label
        .trim()
        .chars()
        .take_while(|c| c.is_ascii_alphabetic())
        .collect();
    ELEMENTS
        .iter()
        .find(|(s, _, _)| s.eq_ignore_ascii_case(&letters))
        .map(|&(_, r, c)| (r, c.map(|v| f64::from(v) / 255.0)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn symbols_in_any_case_and_with_labels() {
        assert_eq!(lookup("C").unwrap().0, 1.70);
        assert_eq!(lookup("cl").unwrap().0, 1.75);
        assert_eq!(
            lookup(" O12 ").unwrap().1,
            [1.0, 13.0 / 255.0, 13.0 / 255.0]
        );
        assert!(lookup("Xx").is_none());
        assert!(lookup("").is_none());
        // Every symbol appears once.
        for (k, (s, _, _)) in ELEMENTS.iter().enumerate() {
            assert!(ELEMENTS[k + 1..].iter().all(|(t, _, _)| t != s), "{s}");
        }
    }
}
