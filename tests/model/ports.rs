//! The Verilog port lists of `specfx_top`, `specfx_pipelined`, `specfx_folded` and
//! `specfx_dut` against the one table of the top's ports (`specfx::pipeline::ports::TOP_PORTS`):
//! the same names in the same order, the same directions, the same widths (the parameter that
//! sizes each port, or its number of bits); and the instances of a top written in Verilog
//! (`specfx_dut`'s of `specfx_top`, the place-and-route harness's of `specfx_dut`) connect
//! every port of the table, in its order. A port added to, removed from or resized in one of
//! them, or in the table, fails here.

use std::path::Path;

use specfx::pipeline::ports::{Direction, TOP_PORTS};

/// The text of `file` under `hdl_ref/`.
fn read(file: &str) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("hdl_ref")
        .join(file);
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The port names an instance (`<module> ... <instance> (` up to `);`) in `file` connects, in
/// the order of its `.port(...)` connections.
fn connected_ports(file: &str, instance: &str) -> Vec<String> {
    let text = read(file);
    let start = text
        .find(&format!("{instance} ("))
        .unwrap_or_else(|| panic!("no instance {instance} in {file}"));
    let close = text[start..].find(");").unwrap() + start;
    text[start..close]
        .split('.')
        .skip(1)
        .map(|c| c.split('(').next().unwrap().trim().to_string())
        .collect()
}

/// `(name, direction, width)` of each port in the ANSI port list of `module` in `file`: the
/// text between `) (` after the module's parameters (or the `(` after its name) and the `);`
/// that closes it. A width is the parameter `X` of `[X-1:0]` (of `` [(`SPECFX_X)-1:0] ``), the
/// number of bits of `[H:0]`, or 1 without a range.
fn verilog_ports(file: &str, module: &str) -> Vec<(String, Direction, String)> {
    let text = read(file);
    let start = text
        .find(&format!("module {module}"))
        .unwrap_or_else(|| panic!("no module {module} in {file}"));
    let rest = &text[start..];
    // After the parameter list `#( ... )` when there is one.
    let open = if rest[format!("module {module}").len()..]
        .trim_start()
        .starts_with('#')
    {
        rest.find(") (").map(|i| i + 3)
    } else {
        rest.find('(').map(|i| i + 1)
    }
    .unwrap_or_else(|| panic!("{file}: no port list"));
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
                    // `C_W`, or `specfx_dut`'s macro `(`SPECFX_C_W)`.
                    Some(param) => param
                        .trim()
                        .trim_start_matches("(`SPECFX_")
                        .trim_end_matches(')')
                        .to_string(),
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
        ("rtl/specfx_top.v", "specfx_top"),
        ("rtl/specfx_pipelined.v", "specfx_pipelined"),
        ("rtl/specfx_folded.v", "specfx_folded"),
        ("specfx_dut.v", "specfx_dut"),
    ] {
        assert_eq!(verilog_ports(file, module), table, "{module} ({file})");
    }
}

#[test]
fn the_verilog_instances_connect_every_port_of_the_table() {
    let names: Vec<String> = TOP_PORTS.iter().map(|p| p.name.to_string()).collect();
    for (file, instance) in [
        ("specfx_dut.v", ") u_top"),
        ("specfx_pnr_top.v", "specfx_dut u_dut"),
    ] {
        assert_eq!(
            connected_ports(file, instance),
            names,
            "{instance} in {file}"
        );
    }
    // The harness written for place and route is that file.
    assert_eq!(
        specfx::hdl::pnr::harness_verilog(),
        read("specfx_pnr_top.v")
    );
}

#[test]
fn a_drifted_port_list_is_caught() {
    // The parser reads what the test compares: a port list with a port resized and one
    // renamed differs from the table.
    let table: Vec<(String, Direction, String)> = TOP_PORTS
        .iter()
        .map(|p| (p.name.to_string(), p.direction, p.verilog_width.to_string()))
        .collect();
    let top = verilog_ports("rtl/specfx_top.v", "specfx_top");
    let mut drifted = top.clone();
    drifted[9].2 = "4".to_string();
    assert_ne!(drifted, table);
    let mut renamed = top;
    renamed[5].0 = "in_slop".to_string();
    assert_ne!(renamed, table);
}
