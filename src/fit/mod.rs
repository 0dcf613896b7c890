pub mod walton;
