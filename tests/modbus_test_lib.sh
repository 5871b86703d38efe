# modbus_test_lib.sh: helpers the Modbus shell tests source: free loopback ports, and the
# configs/modbus-sim machine copied to a temporary INI that runs from anywhere.

# free_base_port N: prints a port P such that P..P+N-1 have no listener on this machine
# (ss from iproute2), starting from a number derived from the shell's pid so parallel
# runs do not start from the same guess.
free_base_port()
{
    n=$1
    p=$((20000 + ($$ * 37) % 30000))
    for try in 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19 20; do
        busy=$(ss -Htln 2>/dev/null | awk '{ sub(/.*:/, "", $4); print $4 }' |
               awk -v lo="$p" -v hi=$((p + n - 1)) '$1 >= lo && $1 <= hi' | head -1)
        [ -z "$busy" ] && { echo "$p"; return 0; }
        p=$((20000 + (p - 20000 + 97) % 30000))
    done
    return 1
}

# machine_ini SRC.ini OUT.ini BASE_PORT [KEY=VALUE in [MODBUS]...]: SRC with every path made
# absolute (so OUT may live in /tmp), LCM off, drives on BASE_PORT.., and the given [MODBUS]
# keys replaced.
machine_ini()
{
    src=$1; out=$2; base=$3; shift 3
    dir=$(cd "$(dirname "$src")" && pwd)
    sed -e "s|^\(HALFILE *= *\)\([^/]\)|\1$dir/\2|" \
        -e "s|^\(TOOL_TABLE *= *\)\([^/]\)|\1$dir/\2|" \
        -e "s|^\(OPEN_FILE *= *\)\([^/]\)|\1$dir/\2|" \
        -e "s|^URL *=.*|URL =|" \
        -e "s|^BASE_PORT *=.*|BASE_PORT = $base|" "$src" > "$out"
    for kv in "$@"; do
        k=${kv%%=*}; v=${kv#*=}
        sed -i "/^\[MODBUS\]/,/^\[/ s|^$k *=.*|$k = $v|" "$out"
    done
}
