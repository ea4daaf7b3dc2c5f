//! The Verilog port lists of `specfx_top`, `specfx_pipelined` and `specfx_folded` against the
//! one table of the top's ports (`specfx::pipeline::ports::TOP_PORTS`): the same names in the
//! same order, the same directions, the same widths (the parameter that sizes each port, or
//! its number of bits). A port added to, removed from or resized in one of them, or in the
//! table, fails here.

use std::path::Path;

use specfx::pipeline::ports::{Direction, TOP_PORTS};

/// `(name, direction, width)` of each port in the ANSI port list of `module` in `file`: the
/// text between `) (` after the module's name and the `);` that closes it. A width is the
/// parameter `X` of `[X-1:0]`, the number of bits of `[H:0]`, or 1 without a range.
fn verilog_ports(file: &str, module: &str) -> Vec<(String, Direction, String)> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("hdl_ref/rtl")
        .join(file);
    let text = std::fs::read_to_string(&path).unwrap();
    let start = text
        .find(&format!("module {module}"))
        .unwrap_or_else(|| panic!("no module {module} in {file}"));
    let rest = &text[start..];
    let open = rest
        .find(") (")
        .unwrap_or_else(|| panic!("{file}: no port list"))
        + 3;
    let close = rest[open..].find(");").unwrap() + open;
    let mut ports = Vec::new();
    for line in rest[open..close].lines() {
        let line = line
            .split("//")
            .next()
            .unwrap()
            .trim()
            .trim_end_matches(',');
        if line.is_empty() {
            continue;
        }
        let words: Vec<&str> = line.split_whitespace().collect();
        let direction = match words[0] {
            "input" => Direction::Input,
            "output" => Direction::Output,
            other => panic!("{file}: '{other}' in the port list of {module}: {line}"),
        };
        let name = words.last().unwrap().to_string();
        let width = match line.find('[') {
            None => "1".to_string(),
            Some(i) => {
                let range = &line[i + 1..line.find(']').unwrap()];
                let (high, low) = range.split_once(':').unwrap();
                assert_eq!(low.trim(), "0", "{file}: {line}");
                match high.trim().strip_suffix("-1") {
                    Some(param) => param.trim().to_string(),
                    None => (high.trim().parse::<u32>().unwrap() + 1).to_string(),
                }
            }
        };
        ports.push((name, direction, width));
    }
    ports
}

#[test]
fn the_verilog_port_lists_are_the_one_table() {
    let table: Vec<(String, Direction, String)> = TOP_PORTS
        .iter()
        .map(|p| (p.name.to_string(), p.direction, p.verilog_width.to_string()))
        .collect();
    for (file, module) in [
        ("specfx_top.v", "specfx_top"),
        ("specfx_pipelined.v", "specfx_pipelined"),
        ("specfx_folded.v", "specfx_folded"),
    ] {
        assert_eq!(verilog_ports(file, module), table, "{module} ({file})");
    }
}

#[test]
fn a_drifted_port_list_is_caught() {
    // The parser reads what the test compares: a port list with a port resized and one
    // renamed differs from the table.
    let table: Vec<(String, Direction, String)> = TOP_PORTS
        .iter()
        .map(|p| (p.name.to_string(), p.direction, p.verilog_width.to_string()))
        .collect();
    let top = verilog_ports("specfx_top.v", "specfx_top");
    let mut drifted = top.clone();
    drifted[9].2 = "4".to_string();
    assert_ne!(drifted, table);
    let mut renamed = top;
    renamed[5].0 = "in_slop".to_string();
    assert_ne!(renamed, table);
}
