//! Prints the complete `modelDescription.xml` of a body (FMI 2.0, or 3.0 with `--fmi 3`) to
//! standard output.
//!
//! Usage: `flexbody-model-description [--body FILE] [--fmi 2|3]`. Without `--body` it describes the embedded
//! default body (`examples/cantilever.json`). `cargo xtask fmu` runs it to build the `.fmu`, so
//! the XML comes from the same code (and the same GUID) as the binary that reads it.
//! On any error the message goes to standard error and the exit code is 1.

use flexbody::model::BodyFile;
use flexbody::slave::Slave;
use std::process::ExitCode;

const USAGE: &str = "usage: flexbody-model-description [--body FILE] [--fmi 2|3]";

/// What the command line asks for.
#[derive(Debug, PartialEq)]
enum Command {
    /// Describe the body in this file, or the embedded default body (`None`).
    Describe {
        body: Option<String>,
        /// The FMI version of the description: 2 or 3.
        fmi: u8,
    },
    Help,
}

/// Parses the arguments after the program name.
fn parse_args(args: impl IntoIterator<Item = String>) -> Result<Command, String> {
    let mut body = None;
    let mut fmi = None;
    let mut args = args.into_iter();
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--body" => {
                let file = args.next().ok_or("--body needs a file name")?;
                if body.replace(file).is_some() {
                    return Err("--body given twice".into());
                }
            }
            "--fmi" => {
                let version = match args.next().as_deref() {
                    Some("2") => 2,
                    Some("3") => 3,
                    _ => return Err("--fmi needs 2 or 3".into()),
                };
                if fmi.replace(version).is_some() {
                    return Err("--fmi given twice".into());
                }
            }
            "-h" | "--help" => return Ok(Command::Help),
            other => return Err(format!("unexpected argument '{other}'")),
        }
    }
    Ok(Command::Describe {
        body,
        fmi: fmi.unwrap_or(2),
    })
}

/// The modelDescription.xml (FMI `fmi`) of the body in `file` (or of the default body).
fn describe(file: Option<&str>, fmi: u8) -> Result<String, String> {
    let slave = match file {
        // A mesh file named by the body file is read from beside it.
        Some(path) => Slave::from_body_path(std::path::Path::new(path)),
        None => Slave::from_body(BodyFile::default_body()),
    }
    .map_err(|e| e.to_string())?;
    Ok(match fmi {
        3 => slave.model_description_fmi3(),
        _ => slave.model_description(),
    })
}

fn main() -> ExitCode {
    let result = parse_args(std::env::args().skip(1)).and_then(|command| match command {
        Command::Help => {
            println!("{USAGE}");
            Ok(())
        }
        Command::Describe { body, fmi } => {
            describe(body.as_deref(), fmi).map(|xml| print!("{xml}"))
        }
    });
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("flexbody-model-description: {message}\n{USAGE}");
            ExitCode::FAILURE
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn args(list: &[&str]) -> Vec<String> {
        list.iter().map(|s| s.to_string()).collect()
    }

    #[test]
    fn no_arguments_describe_the_default_body() {
        assert_eq!(
            parse_args(args(&[])),
            Ok(Command::Describe { body: None, fmi: 2 })
        );
    }

    #[test]
    fn body_option_takes_a_file() {
        assert_eq!(
            parse_args(args(&["--body", "beam.json"])),
            Ok(Command::Describe {
                body: Some("beam.json".into()),
                fmi: 2
            })
        );
    }

    #[test]
    fn fmi_option_takes_2_or_3() {
        assert_eq!(
            parse_args(args(&["--fmi", "3"])),
            Ok(Command::Describe { body: None, fmi: 3 })
        );
        assert!(parse_args(args(&["--fmi", "4"])).is_err());
        assert!(parse_args(args(&["--fmi", "3", "--fmi", "2"])).is_err());
    }

    #[test]
    fn bad_arguments_are_rejected() {
        assert!(parse_args(args(&["--body"])).is_err());
        assert!(parse_args(args(&["--body", "a.json", "--body", "b.json"])).is_err());
        assert!(parse_args(args(&["beam.json"])).is_err());
    }

    #[test]
    fn unreadable_body_file_is_an_error_naming_it() {
        let err = describe(Some("/nonexistent/body.json"), 2).unwrap_err();
        assert!(err.contains("/nonexistent/body.json"), "{err}");
    }
}
