"""`python3 -m rtcost sweep SPEC.json ...`: what `rtcost sweep` runs."""
import sys

if __name__ == "__main__":
    if len(sys.argv) < 2 or sys.argv[1] != "sweep":
        print("usage: python3 -m rtcost sweep SPEC.json [--out FILE] [--scheduler ADDR] [--workers N] [--json]",
              file=sys.stderr)
        sys.exit(2)
    from rtcost._sweep import main
    sys.exit(main(sys.argv[2:]))
