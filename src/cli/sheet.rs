//! `skycast sheet --out FILE`: writes the 16-texture cloud sheet (512 x 512 RGBA PNG).

use std::path::PathBuf;

use anyhow::Context;
use clap::Args;

use skycast::clouds::TextureSheet;

/// Flags of `skycast sheet`.
#[derive(Debug, Args)]
pub struct SheetArgs {
    /// Where to write the PNG.
    #[arg(long)]
    pub out: PathBuf,
    /// Also write the sheet composited over a sky blue, to look at.
    #[arg(long)]
    pub over_sky: Option<PathBuf>,
}

/// Generates the sheet and writes level 0.
pub fn run(args: &SheetArgs) -> anyhow::Result<()> {
    let sheet = TextureSheet::generate();
    sheet.save_png(&args.out)?;
    println!("wrote {}", args.out.display());
    if let Some(path) = &args.over_sky {
        sheet
            .to_image_over([74, 118, 178])
            .save(path)
            .with_context(|| format!("{}: cannot write image", path.display()))?;
        println!("wrote {}", path.display());
    }
    Ok(())
}
