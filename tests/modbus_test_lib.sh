# modbus_test_lib.sh: helpers the Modbus shell tests source: free loopback ports, and the
# configs/modbus-sim machine copied to a temporary INI that runs from anywhere.

# free_base_port N: prints a port P such that no TCP socket of this machine (ss, iproute2)
# uses P..P+N-1, taken from 20000..32000, below the kernel's ephemeral ports (32768 and up)
# that clients use, and above the 10000..19999 of the C and Python tests (test_net_util.h). The first guess comes from the shell's pid
# so parallel runs do not start from the same one. (fb_ prefix: shell functions share the
# caller's variables.)
free_base_port()
{
    fb_n=$1
    fb_p=$((20000 + ($$ * 37) % 12000))
    for fb_try in 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19 20; do
        fb_busy=$(ss -Htan 2>/dev/null | awk '{ sub(/.*:/, "", $4); print $4 }' |
                  awk -v lo="$fb_p" -v hi=$((fb_p + fb_n - 1)) '$1 >= lo && $1 <= hi' | head -1)
        [ -z "$fb_busy" ] && { echo "$fb_p"; return 0; }
        fb_p=$((20000 + (fb_p - 20000 + 97) % 12000))
    done
    return 1
}

# machine_ini SRC.ini OUT.ini BASE_PORT [KEY=VALUE in [MODBUS]...]: SRC with every path made
# absolute (so OUT may live in /tmp), LCM off, drives on BASE_PORT.., and the given [MODBUS]
# keys replaced. (Shell functions share the caller's variables: these use an mi_ prefix.)
machine_ini()
{
    mi_src=$1; mi_out=$2; mi_base=$3; shift 3
    mi_dir=$(cd "$(dirname "$mi_src")" && pwd)
    sed -e "s|^\(HALFILE *= *\)\([^/]\)|\1$mi_dir/\2|" \
        -e "s|^\(TOOL_TABLE *= *\)\([^/]\)|\1$mi_dir/\2|" \
        -e "s|^\(OPEN_FILE *= *\)\([^/]\)|\1$mi_dir/\2|" \
        -e "s|^URL *=.*|URL =|" \
        -e "s|^BASE_PORT *=.*|BASE_PORT = $mi_base|" "$mi_src" > "$mi_out"
    for mi_kv in "$@"; do
        mi_k=${mi_kv%%=*}; mi_v=${mi_kv#*=}
        sed -i "/^\[MODBUS\]/,/^\[/ s|^$mi_k *=.*|$mi_k = $mi_v|" "$mi_out"
    done
}
