//! Variants and overrides of a scenario, so that one file serves a whole study.
//!
//! A scenario may carry a `[variants]` table: groups of named TOML fragments,
//!
//! ```toml
//! [variants.concrete.mazars.materials.concrete]
//! model = "mazars"
//! ```
//!
//! `--variant concrete=mazars` merges the fragment into the scenario before it is
//! validated: tables merge key by key (recursively), arrays of tables element by
//! element (the fragment's first table into the scenario's first, and so on; extra
//! elements are appended), every other value replaces the scenario's. A group's
//! option may be empty: it names the scenario as written. The `[variants]` table
//! itself is never part of the model.
//!
//! `--set dotted.path=value` then replaces one value: `analysis.dt=5e-7`,
//! `meshing.element_size=0.1`, `bodies.steel.velocity=[0.0, -2.0]` (an array of tables
//! is indexed by position, `bodies.1`, or by the `name` of its element). The value is
//! read as TOML (a number, a boolean, an array, an inline table, a quoted string);
//! anything that does not parse as TOML is taken as a bare string (`model=mazars`).

use toml::{Table, Value};

use crate::error::{Error, Result};

/// The variants to select and the values to set, in the order given.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Overrides {
    /// `(group, option)` pairs of `--variant group=option`.
    pub variants: Vec<(String, String)>,
    /// Dotted paths of `--unset path`, removed before the values are set.
    #[serde(default)]
    pub unsets: Vec<String>,
    /// `(dotted path, TOML value text)` pairs of `--set path=value`.
    pub sets: Vec<(String, String)>,
}

impl Overrides {
    /// None.
    pub fn none() -> Self {
        Overrides::default()
    }

    /// Nothing to apply.
    pub fn is_empty(&self) -> bool {
        self.variants.is_empty() && self.sets.is_empty() && self.unsets.is_empty()
    }

    /// Adds a dotted path to remove.
    pub fn unset(mut self, path: &str) -> Self {
        self.unsets.push(path.trim().to_string());
        self
    }

    /// These overrides followed by `more`'s.
    pub fn then(&self, more: &Overrides) -> Overrides {
        let mut o = self.clone();
        o.variants.extend(more.variants.iter().cloned());
        o.unsets.extend(more.unsets.iter().cloned());
        o.sets.extend(more.sets.iter().cloned());
        o
    }

    /// Adds `group=option` (as typed on the command line).
    pub fn variant(mut self, spec: &str) -> Result<Self> {
        let (g, o) = split_assignment("--variant", spec)?;
        self.variants.push((g, o));
        Ok(self)
    }

    /// Adds `path=value` (as typed on the command line).
    pub fn set(mut self, spec: &str) -> Result<Self> {
        let (p, v) = split_assignment("--set", spec)?;
        self.sets.push((p, v));
        Ok(self)
    }

    /// The command-line arguments that give these overrides (`--variant g=o`,
    /// `--set p=v`), for the run lists a study emits.
    pub fn to_args(&self) -> Vec<String> {
        let mut args = Vec::new();
        for (g, o) in &self.variants {
            args.push("--variant".into());
            args.push(format!("{g}={o}"));
        }
        for p in &self.unsets {
            args.push("--unset".into());
            args.push(p.clone());
        }
        for (p, v) in &self.sets {
            args.push("--set".into());
            args.push(format!("{p}={v}"));
        }
        args
    }
}

fn split_assignment(flag: &str, spec: &str) -> Result<(String, String)> {
    match spec.split_once('=') {
        Some((k, v)) if !k.trim().is_empty() && !v.trim().is_empty() => {
            Ok((k.trim().to_string(), v.trim().to_string()))
        }
        _ => Err(Error::config(
            flag,
            format!("expected `name=value`, got `{spec}`"),
        )),
    }
}

/// Applies `ov` to a parsed scenario table and removes its `[variants]` table.
pub fn apply(mut table: Table, ov: &Overrides) -> Result<Table> {
    let variants = match table.remove("variants") {
        None => Table::new(),
        Some(Value::Table(t)) => t,
        Some(_) => {
            return Err(Error::config(
                "variants",
                "must be a table of groups ([variants.<group>.<option>])",
            ))
        }
    };
    for (i, (group, option)) in ov.variants.iter().enumerate() {
        if let Some((_, first)) = ov.variants[..i].iter().find(|(g, _)| g == group) {
            return Err(Error::config(
                "--variant",
                format!(
                    "variant group `{group}` is selected twice (`{first}` and `{option}`): \
                     a group takes one option"
                ),
            ));
        }
        let options = match variants.get(group) {
            Some(Value::Table(t)) => t,
            Some(_) => {
                return Err(Error::config(
                    format!("variants.{group}"),
                    "must be a table of options",
                ))
            }
            None => {
                let known: Vec<&str> = variants.keys().map(String::as_str).collect();
                return Err(Error::config(
                    "--variant",
                    format!(
                        "the scenario has no variant group `{group}` (it has: {})",
                        list(&known)
                    ),
                ));
            }
        };
        match options.get(option) {
            Some(Value::Table(fragment)) => merge_table(&mut table, fragment),
            Some(_) => {
                return Err(Error::config(
                    format!("variants.{group}.{option}"),
                    "must be a table (a fragment of the scenario)",
                ))
            }
            None => {
                let known: Vec<&str> = options.keys().map(String::as_str).collect();
                return Err(Error::config(
                    "--variant",
                    format!(
                        "variant group `{group}` has no option `{option}` (it has: {})",
                        list(&known)
                    ),
                ));
            }
        }
    }
    for path in &ov.unsets {
        unset_path(&mut table, path)?;
    }
    for (path, text) in &ov.sets {
        set_path(&mut table, path, parse_value(text))?;
    }
    Ok(table)
}

fn list(names: &[&str]) -> String {
    if names.is_empty() {
        "none".into()
    } else {
        names.join(", ")
    }
}

/// A value typed on the command line: TOML when it parses, else a bare string.
fn parse_value(text: &str) -> Value {
    match format!("v = {text}").parse::<Table>() {
        Ok(mut t) => t.remove("v").unwrap_or_else(|| Value::String(text.into())),
        Err(_) => Value::String(text.into()),
    }
}

/// Merges `src` into `dst`: tables key by key, arrays of tables element by element,
/// other values replaced.
fn merge_table(dst: &mut Table, src: &Table) {
    for (k, v) in src {
        match dst.get_mut(k) {
            Some(d) => merge_value(d, v),
            None => {
                dst.insert(k.clone(), v.clone());
            }
        }
    }
}

fn merge_value(dst: &mut Value, src: &Value) {
    match (dst, src) {
        (Value::Table(d), Value::Table(s)) => merge_table(d, s),
        (Value::Array(d), Value::Array(s))
            if s.iter().all(Value::is_table) && d.iter().all(Value::is_table) =>
        {
            for (i, sv) in s.iter().enumerate() {
                match d.get_mut(i) {
                    Some(dv) => merge_value(dv, sv),
                    None => d.push(sv.clone()),
                }
            }
        }
        (d, s) => *d = s.clone(),
    }
}

/// Sets the value at a dotted path, creating tables on the way (not array elements).
fn set_path(table: &mut Table, path: &str, value: Value) -> Result<()> {
    let keys: Vec<&str> = path.split('.').collect();
    if keys.iter().any(|k| k.is_empty()) {
        return Err(Error::config(
            "--set",
            format!("`{path}` is not a dotted path"),
        ));
    }
    let mut cur = table;
    for (depth, key) in keys[..keys.len() - 1].iter().enumerate() {
        let here = keys[..=depth].join(".");
        let next = cur
            .entry(key.to_string())
            .or_insert_with(|| Value::Table(Table::new()));
        cur = match next {
            Value::Table(t) => t,
            Value::Array(items) => {
                let seg = keys[depth + 1];
                let idx = array_index(items, seg).ok_or_else(|| {
                    Error::config(
                        "--set",
                        format!(
                            "`{here}` has {} elements and none is `{seg}` (give an index or a name)",
                            items.len()
                        ),
                    )
                })?;
                if depth + 2 == keys.len() {
                    items[idx] = value;
                    return Ok(());
                }
                return match &mut items[idx] {
                    Value::Table(t) => set_path(t, &keys[depth + 2..].join("."), value),
                    _ => Err(Error::config(
                        "--set",
                        format!("`{here}.{seg}` is not a table"),
                    )),
                };
            }
            _ => {
                return Err(Error::config(
                    "--set",
                    format!("`{here}` is a value, not a table"),
                ))
            }
        };
    }
    cur.insert(keys[keys.len() - 1].to_string(), value);
    Ok(())
}

/// Removes the key at a dotted path of tables (or of named or numbered elements of
/// arrays of tables, as `--set` reaches them). A path the scenario does not have is
/// an error naming it and what the table holds: a misspelt `--unset` must not pass
/// as a no-op.
fn unset_path(table: &mut Table, path: &str) -> Result<()> {
    let keys: Vec<&str> = path.split('.').collect();
    if keys.iter().any(|k| k.is_empty()) {
        return Err(Error::config(
            "--unset",
            format!("`{path}` is not a dotted path"),
        ));
    }
    let missing = |here: &str, key: &str, t: &Table| {
        let known: Vec<&str> = t.keys().map(String::as_str).collect();
        Error::config(
            "--unset",
            format!(
                "`{path}`: {} has no key `{key}` (it has: {})",
                if here.is_empty() {
                    "the scenario".to_string()
                } else {
                    format!("`{here}`")
                },
                list(&known)
            ),
        )
    };
    let mut cur = table;
    let mut depth = 0;
    while depth + 1 < keys.len() {
        let here = keys[..depth].join(".");
        let key = keys[depth];
        if !cur.contains_key(key) {
            return Err(missing(&here, key, cur));
        }
        cur = match cur.get_mut(key) {
            Some(Value::Table(t)) => {
                depth += 1;
                t
            }
            Some(Value::Array(items)) => {
                let seg = keys[depth + 1];
                let n = items.len();
                let idx = array_index(items, seg).ok_or_else(|| {
                    Error::config(
                        "--unset",
                        format!("`{path}`: `{key}` has {n} elements and none is `{seg}`"),
                    )
                })?;
                if depth + 2 == keys.len() {
                    items.remove(idx);
                    return Ok(());
                }
                depth += 2;
                match &mut items[idx] {
                    Value::Table(t) => t,
                    _ => {
                        return Err(Error::config(
                            "--unset",
                            format!("`{path}`: `{key}.{seg}` is not a table"),
                        ))
                    }
                }
            }
            _ => {
                return Err(Error::config(
                    "--unset",
                    format!("`{path}`: `{key}` is not a table"),
                ))
            }
        };
    }
    let key = keys[keys.len() - 1];
    if cur.remove(key).is_none() {
        return Err(missing(&keys[..keys.len() - 1].join("."), key, cur));
    }
    Ok(())
}

/// Whether the merged scenario `table` has a value at the dotted path of tables.
pub fn has_path(table: &Table, path: &str) -> bool {
    let mut cur = table;
    let keys: Vec<&str> = path.split('.').collect();
    for key in &keys[..keys.len() - 1] {
        match cur.get(*key) {
            Some(Value::Table(t)) => cur = t,
            _ => return false,
        }
    }
    cur.contains_key(keys[keys.len() - 1])
}

/// The element of an array of tables named by position or by its `name` key.
fn array_index(items: &[Value], seg: &str) -> Option<usize> {
    if let Ok(i) = seg.parse::<usize>() {
        return (i < items.len()).then_some(i);
    }
    items
        .iter()
        .position(|v| v.get("name").and_then(Value::as_str) == Some(seg))
}

#[cfg(test)]
mod tests {
    use super::*;

    const BASE: &str = r#"
[analysis]
dt = 1e-6
[materials.concrete]
model = "elastic"
E = 33e9
[[bodies]]
name = "concrete"
velocity = [0.0, 0.0]
[[bodies]]
name = "steel"
velocity = [0.0, -3.0]
[variants.concrete.elastic]
[variants.concrete.kv.materials.concrete]
model = "kelvin_voigt"
beta = 1e6
[[variants.speed.fast.bodies]]
[[variants.speed.fast.bodies]]
velocity = [0.0, -6.0]
"#;

    fn table() -> Table {
        BASE.parse().unwrap()
    }

    #[test]
    fn a_variant_merges_tables_and_arrays_of_tables() {
        let ov = Overrides::none()
            .variant("concrete=kv")
            .unwrap()
            .variant("speed=fast")
            .unwrap();
        let t = apply(table(), &ov).unwrap();
        assert!(t.get("variants").is_none());
        let c = &t["materials"]["concrete"];
        assert_eq!(c["model"].as_str(), Some("kelvin_voigt"));
        assert_eq!(c["E"].as_float(), Some(33e9));
        assert_eq!(c["beta"].as_float(), Some(1e6));
        let bodies = t["bodies"].as_array().unwrap();
        assert_eq!(bodies.len(), 2);
        assert_eq!(bodies[0]["name"].as_str(), Some("concrete"));
        assert_eq!(bodies[1]["velocity"][1].as_float(), Some(-6.0));
        // The empty option is the scenario as written.
        let e = apply(
            table(),
            &Overrides::none().variant("concrete=elastic").unwrap(),
        )
        .unwrap();
        assert_eq!(
            e["materials"]["concrete"]["model"].as_str(),
            Some("elastic")
        );
    }

    #[test]
    fn set_reaches_tables_and_named_array_elements() {
        let ov = Overrides::none()
            .set("analysis.dt=5e-7")
            .unwrap()
            .set("bodies.steel.velocity=[0.0, -1.0]")
            .unwrap()
            .set("bodies.0.name=base")
            .unwrap()
            .set("meshing.element_size=0.1")
            .unwrap()
            .set("materials.concrete.model=mazars")
            .unwrap();
        let t = apply(table(), &ov).unwrap();
        assert_eq!(t["analysis"]["dt"].as_float(), Some(5e-7));
        assert_eq!(t["bodies"][1]["velocity"][1].as_float(), Some(-1.0));
        assert_eq!(t["bodies"][0]["name"].as_str(), Some("base"));
        assert_eq!(t["meshing"]["element_size"].as_float(), Some(0.1));
        assert_eq!(t["materials"]["concrete"]["model"].as_str(), Some("mazars"));
        let u = apply(table(), &Overrides::none().unset("analysis.dt")).unwrap();
        assert!(u["analysis"].get("dt").is_none());
        // A path the scenario does not have is named, with what the table holds.
        for (path, words) in [
            ("x.y", "the scenario has no key `x`"),
            ("analysis.dtt", "`analysis` has no key `dtt`"),
            ("bodies.nobody.velocity", "none is `nobody`"),
        ] {
            let e = apply(table(), &Overrides::none().unset(path))
                .unwrap_err()
                .to_string();
            assert!(e.contains("--unset") && e.contains(words), "{e}");
        }
        let v = apply(table(), &Overrides::none().unset("bodies.steel.velocity")).unwrap();
        assert!(v["bodies"][1].get("velocity").is_none());
        assert_eq!(
            ov.to_args(),
            [
                "--set",
                "analysis.dt=5e-7",
                "--set",
                "bodies.steel.velocity=[0.0, -1.0]",
                "--set",
                "bodies.0.name=base",
                "--set",
                "meshing.element_size=0.1",
                "--set",
                "materials.concrete.model=mazars"
            ]
        );
    }

    #[test]
    fn unknown_groups_options_and_paths_are_named() {
        let err = |ov: Overrides| apply(table(), &ov).unwrap_err().to_string();
        let e = err(Overrides::none().variant("model=mazars").unwrap());
        assert!(
            e.contains("no variant group `model`") && e.contains("concrete, speed"),
            "{e}"
        );
        let e = err(Overrides::none().variant("concrete=rh").unwrap());
        assert!(
            e.contains("no option `rh`") && e.contains("elastic, kv"),
            "{e}"
        );
        let e = err(Overrides::none().set("bodies.wood.velocity=1").unwrap());
        assert!(e.contains("none is `wood`"), "{e}");
        let e = err(Overrides::none().set("analysis.dt.x=1").unwrap());
        assert!(e.contains("`analysis.dt` is a value"), "{e}");
        assert!(Overrides::none().set("dt").is_err());
        assert!(Overrides::none().variant("=x").is_err());
        // One group selected twice.
        let e = err(Overrides::none()
            .variant("concrete=elastic")
            .unwrap()
            .variant("concrete=kv")
            .unwrap());
        assert!(
            e.contains("`concrete` is selected twice (`elastic` and `kv`)"),
            "{e}"
        );
    }
}
