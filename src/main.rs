//! The `caustic` command line: render scenes to images, export patches as OBJ, benchmark, or
//! open the viewer. Parsing and the commands live in `src/cli/`.

mod cli;

fn main() -> anyhow::Result<()> {
    cli::run()
}
