use specfx::pipeline::{Config, Datapath, ProbeColumns};
fn main() {
    let dp = Datapath::new(Config::baseline()).unwrap();
    let codes: Vec<i64> = (0..=32768).collect();
    let mut cols = ProbeColumns::default();
    let t = std::time::Instant::now();
    let mut acc = 0i64;
    for nc in dp.constants() {
        for chunk in codes.chunks(4096) {
            dp.eval_batch(nc, chunk, &mut cols);
            acc = acc.wrapping_add(cols.values[8].iter().sum::<i64>());
        }
    }
    println!("batch: {:?} ({acc})", t.elapsed());
    let t = std::time::Instant::now();
    let mut s = 0.0;
    for nc in dp.constants() {
        for c in 1..=32768i64 {
            s += ((c as f64) / 32768.0).powi(nc.n as i32);
        }
    }
    println!("powi: {:?} ({s})", t.elapsed());
}
