//! A reader that closes `cosim`'s standard output early (`cosim inspect RUN --particle 0 | head`) ends the command
//! with no panic message and no backtrace. `println!` panics when it cannot write: the panic still unwinds (a `cosim
//! run` kills its nodes on the way out, as on any error), only its report is replaced, by nothing for a closed pipe,
//! as Unix tools say nothing then, and by one line for any other failure to write (a full disk under `> file`).
//! Found 2026-12-07: `cosim inspect … | head` printed a panic and a 7-frame backtrace.

/// Install the panic report above, around the default one for every other panic.
pub fn quiet_on_closed_stdout() {
    let default = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let payload = info.payload();
        let text = payload
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| payload.downcast_ref::<&str>().copied())
            .unwrap_or_default();
        match text.strip_prefix("failed printing to stdout: ") {
            Some(why) if why.contains("os error 32") => {}
            Some(why) => eprintln!("cosim: cannot write to standard output: {why}"),
            None => default(info),
        }
    }));
}
