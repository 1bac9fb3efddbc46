fn main() {
    let p = std::env::args().nth(1).unwrap();
    let src = std::fs::read_to_string(&p).unwrap();
    let r = lsyc::parser::parse(&src);
    println!("{:#?}", r.file);
    print!(
        "{}",
        lsyc::diagnostic::render(
            &r.diagnostics,
            &p,
            &src,
            lsyc::diagnostic::Format::Human { color: false }
        )
    );
}
