//! Host side of the golden check: prints the same `golden <name> <hex>...` lines as the
//! firmware. `cargo run -q -p faint-golden --example golden`.

fn main() {
    let mut line = String::new();
    faint_golden::cases(&mut |name, words| {
        line.clear();
        faint_golden::write_line(&mut line, name, words).expect("writing to a String");
        println!("{line}");
    });
}
