use clap::Parser;

fn main() {
    let cli = robocal::cli::Cli::parse();
    if let Err(e) = robocal::cli::run(cli) {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}
