//! LLV benchmarks (to be written).
fn main() {
    divan::main();
}
